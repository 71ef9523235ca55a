//! The Galerkin grid operator.
