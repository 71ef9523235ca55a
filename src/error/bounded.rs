//! Values echoed in messages, cut to a readable length: what every message of the crate's
//! errors that carries text from a file goes through. Also compiled into the program
//! (`src/bin/precursors.rs`, `#[path]`), whose report bounds the causes it prints the same
//! way; it uses nothing but `std`.

/// A quoted value longer than this (in characters) is cut in a message.
const LONGEST_VALUE: usize = 120;
/// A cut value keeps its first this many characters (then `... (N bytes)`): a cut value
/// is no longer than [`LONGEST_VALUE`], so cutting twice changes nothing.
const KEPT: usize = 80;
/// Text between quoted values longer than this is cut too: the messages' own prose is
/// shorter, so only a value that holds quote characters itself reaches it.
const LONGEST_PROSE: usize = 1000;
/// Whatever its pieces, a message longer than this (in bytes) is cut as a whole.
const LONGEST_MESSAGE: usize = 4096;

/// `text` (a message, or a value to echo in one) with every value quoted in it (between
/// backticks, or between double quotes with backslash escapes, as the JSON parser and
/// `{:?}` quote) longer than [`LONGEST_VALUE`] characters cut to its first [`KEPT`] and its
/// length: `"aaaa... (104857600 bytes)"`. A scene file can hold a 100 MB string, and the
/// parser echoes an unknown variant or field whole. Every message of the crate's errors that
/// carries text from a file goes through it, and so does the program's report of an
/// error's causes.
pub(crate) fn bounded(text: &str) -> std::borrow::Cow<'_, str> {
    fn push_cut(out: &mut String, piece: &str, longest: usize) {
        match piece.char_indices().nth(longest) {
            None => out.push_str(piece),
            Some(_) => {
                let end = piece
                    .char_indices()
                    .nth(KEPT)
                    .map_or(piece.len(), |(i, _)| i);
                out.push_str(&piece[..end]);
                out.push_str(&format!("... ({} bytes)", piece.len()));
            }
        }
    }
    /// The byte index of the quote closing the one at `open` (or `text.len()`).
    fn closing(text: &str, open: usize) -> usize {
        let bytes = text.as_bytes();
        let quote = bytes[open];
        let mut i = open + 1;
        while i < bytes.len() && bytes[i] != quote {
            // A backslash escapes the next character in double quotes (`{:?}`, JSON).
            i += if quote == b'"' && bytes[i] == b'\\' {
                2
            } else {
                1
            };
        }
        i.min(bytes.len())
    }
    if text.len() <= KEPT {
        return text.into();
    }
    let mut out = String::new();
    let mut prose = 0;
    let mut i = 0;
    let bytes = text.as_bytes();
    while i < bytes.len() {
        if bytes[i] == b'`' || bytes[i] == b'"' {
            push_cut(&mut out, &text[prose..i], LONGEST_PROSE);
            let end = closing(text, i);
            out.push(char::from(bytes[i]));
            push_cut(&mut out, &text[i + 1..end], LONGEST_VALUE);
            if end < bytes.len() {
                out.push(char::from(bytes[end]));
            }
            i = end + 1;
            prose = i.min(bytes.len());
        } else {
            i += 1;
        }
    }
    push_cut(&mut out, &text[prose..], LONGEST_PROSE);
    if out.len() > LONGEST_MESSAGE {
        let whole = out;
        out = String::new();
        push_cut(&mut out, &whole, KEPT);
    }
    if out == text {
        text.into()
    } else {
        out.into()
    }
}

/// Displays [`bounded`] text: `format!("{}", Bounded(reason))`.
pub(crate) struct Bounded<'a>(pub(crate) &'a str);

impl std::fmt::Display for Bounded<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&bounded(self.0))
    }
}
