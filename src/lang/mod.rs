//! Scene language: tokens, directives, parameter lists, Include splicing and diagnostics.
//!
//! - [`lexer`]: bytes to tokens (pbrt-v3's tokenizer rules), and fast number parsing.
//! - [`params`]: typed parameter lists (`"type name" value…`).
//! - [`parser`]: tokens to [`parser::Stmt`]s; the directive table; Include splicing
//!   (a directive's parameter list: `parser/param_list.rs`).
//! - [`source`]: loaded files, locations, Include chains, located miette diagnostics.
//!
//! This part knows nothing about rendering; [`crate::loader`] gives the statements meaning.

pub mod lexer;
pub mod params;
pub mod parser;
pub mod source;

pub use parser::{DirKind, Directive, FileLoader, Parser, Stmt, DIRECTIVES};
pub use source::{Loc, SourceMap};

/// Diagnostics gathered while loading a scene.
#[derive(Debug, Default)]
pub struct Diags {
    pub errors: Vec<miette::Report>,
    pub warnings: Vec<miette::Report>,
}

/// Parses a scene text (following Includes through `loader`): statements, the
/// source map and the diagnostics. Mostly for tests, fuzzing and benchmarks.
pub fn parse_text(
    text: &str,
    path: &std::path::Path,
    loader: &dyn FileLoader,
) -> (Vec<Stmt>, SourceMap, Diags) {
    let mut p = Parser::new(path, std::sync::Arc::from(text), loader);
    let stmts = p.parse();
    (stmts, p.sources, p.diags)
}
