//! From tokens or text to a [`Spec`](spec::Spec): the input limits ([`limits`]), the bounded
//! reader of `.mech` text ([`source`]), the grammar ([`parse`]) and the syntax tree it builds
//! ([`spec`]). Only syntax is checked here; [`check`](crate::check) does the rest.

pub mod limits;
pub mod parse;
pub mod source;
pub mod spec;
