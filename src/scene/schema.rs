//! The scene's schema: the one definition of the scene's keys, from which the scene file
//! (`docs/scene-format.md`), the checkpoint's scene identity and the sweeps' axes derive.
//!
//! The types of the scene file (`scene/file.rs`) are declared through `schema_struct!`
//! and `schema_enum!`: one field list gives the serde form (the file; feature `serde`),
//! the walk of every key with its exact value ([`Schema::keys`]: with the fields declared
//! `[observer]` left out, [`Walk::Identity`], the checkpoint's identity, `file::identity`), the typed setter of a dotted
//! key ([`Schema::set`]: a sweep's axes; feature `serde`) and where the file has objects
//! ([`Schema::object_at`]: the shape check that refuses positional arrays). This file
//! holds the machinery and the leaves; `scene/file.rs` the file's types and what derives
//! from them.

use crate::interface::AreaLaw;

/// Which keys a walk of the schema ([`Schema::keys`]) gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Walk {
    /// Every key of the file.
    All,
    /// The keys of the scene's identity: all but the observers, the fields declared
    /// `[observer]` in `schema_struct!` (keys that do not change a run's events: the
    /// solver's parallelism, with results bit for bit the same for every choice; the
    /// probes and the recordings, which observe; the cell limit, a bound, not a value).
    /// A checkpoint resumes across them.
    Identity,
}

/// A node of the scene's schema: a value of the scene file.
pub(crate) trait Schema {
    /// Appends `(dotted key path, exact value)` for every leaf below `path` that `walk`
    /// gives: floats as `{:?}` (which round-trips), counts in decimal, kinds and names in
    /// lower case.
    fn keys(&self, path: &str, walk: Walk, out: &mut Vec<(String, String)>);

    /// Sets the value at the key path `rest` below this node (at the dotted path `at`),
    /// read as the file reads it.
    ///
    /// # Errors
    /// [`KeyError`]: no such key, a key below a value that is not an object, a value the
    /// key's type does not take.
    #[cfg(feature = "serde")]
    fn set(&mut self, at: &str, rest: &[&str], value: &serde_json::Value) -> Result<(), KeyError>;

    /// Whether the file has an object (of named keys) at the key path `rest` below this
    /// node's type (`#` steps into an array's elements).
    #[cfg(feature = "serde")]
    fn object_at(rest: &[&str]) -> bool;
}

/// Why a sweep's key could not be set in a scene.
#[cfg(feature = "serde")]
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub(crate) enum KeyError {
    /// The object at the key's path has no such key.
    #[error("not a scene key: {place} has no `{segment}` (it has: {known})")]
    NotAKey {
        /// `the scene` or the object's path in backquotes.
        place: String,
        /// The missing key.
        segment: String,
        /// The object's keys, sorted and joined.
        known: String,
    },
    /// The key goes below a value that is not an object.
    #[error("`{at}` is not an object of the scene: it has no key `{segment}`")]
    NotAnObject {
        /// The value's path.
        at: String,
        /// The key asked below it.
        segment: String,
    },
    /// The value is not one of the key's type (serde's message, with the value).
    #[error(transparent)]
    Value(#[from] serde_json::Error),
}

#[cfg(feature = "serde")]
impl KeyError {
    /// [`KeyError::NotAKey`] for `segment` in the object at `at` with the keys `known`.
    pub(crate) fn not_a_key(at: &str, segment: &str, known: &[&str]) -> KeyError {
        let mut known = known.to_vec();
        known.sort_unstable();
        KeyError::NotAKey {
            place: if at.is_empty() {
                "the scene".to_string()
            } else {
                format!("`{at}`")
            },
            segment: segment.to_string(),
            known: known.join(", "),
        }
    }
}

/// `path.key` (`key` at the top).
pub(crate) fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// Replaces `node` by `value` read as the file reads it.
#[cfg(feature = "serde")]
pub(crate) fn replace<T: serde::de::DeserializeOwned>(
    node: &mut T,
    value: &serde_json::Value,
) -> Result<(), KeyError> {
    *node = T::deserialize(value)?;
    Ok(())
}

/// A leaf: a value without keys below it, written exactly by `exact`; or, with `walk`
/// before the function, by a function of the value and the walk (a value whose identity
/// is another value's: the backend `cuda` runs the `spectral` rule).
macro_rules! schema_leaf {
    ($ty:ty, $exact:expr) => {
        schema_leaf!($ty, walk | v: &$ty, _: $crate::scene::schema::Walk | {
            let exact: fn(&$ty) -> String = $exact;
            exact(v)
        });
    };
    ($ty:ty, walk $exact:expr) => {
        impl $crate::scene::schema::Schema for $ty {
            fn keys(
                &self,
                path: &str,
                walk: $crate::scene::schema::Walk,
                out: &mut Vec<(String, String)>,
            ) {
                let exact: fn(&$ty, $crate::scene::schema::Walk) -> String = $exact;
                out.push((path.to_string(), exact(self, walk)));
            }

            #[cfg(feature = "serde")]
            fn set(
                &mut self,
                at: &str,
                rest: &[&str],
                value: &serde_json::Value,
            ) -> Result<(), $crate::scene::schema::KeyError> {
                use $crate::scene::schema::{replace, KeyError};
                match rest {
                    [] => replace(self, value),
                    [segment, ..] => Err(KeyError::NotAnObject {
                        at: at.to_string(),
                        segment: segment.to_string(),
                    }),
                }
            }

            #[cfg(feature = "serde")]
            fn object_at(_: &[&str]) -> bool {
                false
            }
        }
    };
}

schema_leaf!(f64, |v| format!("{v:?}"));
schema_leaf!(usize, |v| format!("{v}"));
schema_leaf!(u64, |v| format!("{v}"));
schema_leaf!(bool, |v| format!("{v}"));
schema_leaf!(Vec<f64>, |v| format!("{v:?}"));
schema_leaf!(Vec<[f64; 3]>, |v| format!("{v:?}"));
schema_leaf!(std::path::PathBuf, |v| format!("{}", v.display()));
schema_leaf!(AreaLaw, |v| format!("{v:?}").to_lowercase());

/// Declares a struct of the scene file (an object of named keys) and its [`Schema`]: the
/// field names are the file's keys. A field written `[observer] name: Type` is an
/// observer: left out of the identity walk ([`Walk::Identity`]), with all below it.
macro_rules! schema_struct {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $( $(#[$field_meta:meta])* $([$role:ident])? $field:ident : $ty:ty ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        $vis struct $name {
            $( $(#[$field_meta])* $field: $ty ),*
        }

        impl $crate::scene::schema::Schema for $name {
            fn keys(
                &self,
                path: &str,
                walk: $crate::scene::schema::Walk,
                out: &mut Vec<(String, String)>,
            ) {
                use $crate::scene::schema::{join, schema_role, Walk};
                $(
                    if walk == Walk::All || !schema_role!($($role)?) {
                        self.$field.keys(&join(path, stringify!($field)), walk, out);
                    }
                )*
            }

            #[cfg(feature = "serde")]
            fn set(
                &mut self,
                at: &str,
                rest: &[&str],
                value: &serde_json::Value,
            ) -> Result<(), $crate::scene::schema::KeyError> {
                use $crate::scene::schema::{join, replace, KeyError};
                match rest {
                    [] => replace(self, value),
                    [segment, rest @ ..] => match *segment {
                        $( s if s == stringify!($field) => {
                            self.$field.set(&join(at, s), rest, value)
                        } )*
                        s => Err(KeyError::not_a_key(at, s, &[$(stringify!($field)),*])),
                    },
                }
            }

            #[cfg(feature = "serde")]
            fn object_at(rest: &[&str]) -> bool {
                match rest {
                    [] => true,
                    [segment, rest @ ..] => match *segment {
                        $( s if s == stringify!($field) => {
                            <$ty as $crate::scene::schema::Schema>::object_at(rest)
                        } )*
                        _ => false,
                    },
                }
            }
        }
    };
}

/// Declares an enum of the scene file (an object whose key `kind` names the variant,
/// given as a literal, and the variant's keys) and its [`Schema`].
macro_rules! schema_enum {
    (
        $(#[$meta:meta])*
        $vis:vis enum $name:ident {
            $( $variant:ident = $kind:literal {
                $( $(#[$field_meta:meta])* $field:ident : $ty:ty ),* $(,)?
            } ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        $vis enum $name {
            $(
                #[cfg_attr(feature = "serde", serde(rename = $kind))]
                $variant { $( $(#[$field_meta])* $field: $ty ),* }
            ),*
        }

        impl $crate::scene::schema::Schema for $name {
            fn keys(
                &self,
                path: &str,
                walk: $crate::scene::schema::Walk,
                out: &mut Vec<(String, String)>,
            ) {
                use $crate::scene::schema::join;
                out.push((join(path, "kind"), self.kind().to_string()));
                match self {
                    $( $name::$variant { $($field),* } => {
                        $( $field.keys(&join(path, stringify!($field)), walk, out); )*
                    } )*
                }
            }

            #[cfg(feature = "serde")]
            fn set(
                &mut self,
                at: &str,
                rest: &[&str],
                value: &serde_json::Value,
            ) -> Result<(), $crate::scene::schema::KeyError> {
                use $crate::scene::schema::{join, replace, KeyError};
                match rest {
                    [] => replace(self, value),
                    // Another kind, with this variant's other keys, read again (a kind
                    // without keys may follow another without keys).
                    ["kind"] => {
                        let mut object = serde_json::to_value(&*self)?;
                        object["kind"] = value.clone();
                        replace(self, &object)
                    }
                    ["kind", segment, ..] => Err(KeyError::NotAnObject {
                        at: join(at, "kind"),
                        segment: segment.to_string(),
                    }),
                    [segment, rest @ ..] => match self {
                        $( $name::$variant { $($field),* } => match *segment {
                            $( s if s == stringify!($field) => {
                                $field.set(&join(at, s), rest, value)
                            } )*
                            s => Err(KeyError::not_a_key(
                                at,
                                s,
                                &["kind", $(stringify!($field)),*],
                            )),
                        }, )*
                    },
                }
            }

            #[cfg(feature = "serde")]
            fn object_at(rest: &[&str]) -> bool {
                match rest {
                    [] => true,
                    [segment, rest @ ..] => {
                        false $( $( || (*segment == stringify!($field)
                            && <$ty as $crate::scene::schema::Schema>::object_at(rest)) )* )*
                    }
                }
            }
        }

        impl $name {
            /// The `kind` of this variant in the file.
            fn kind(&self) -> &'static str {
                match self {
                    $( $name::$variant { .. } => $kind, )*
                }
            }
        }
    };
}

/// Whether a field of `schema_struct!` is an observer: `[observer]` before its name.
macro_rules! schema_role {
    () => {
        false
    };
    (observer) => {
        true
    };
}

pub(crate) use {schema_enum, schema_leaf, schema_role, schema_struct};
