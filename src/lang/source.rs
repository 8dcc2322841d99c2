//! Loaded source files, locations, Include chains and located diagnostics.
//!
//! Every token carries a [`Loc`]: the file, the byte span and the Include chain it
//! came through. Diagnostics are built from a `Loc` into a [`miette::Report`] whose
//! message starts with `FILE:LINE:COL`, whose snippet shows the line, and whose help
//! lists the Include lines (`included from FILE:LINE:COL`).

use miette::{
    Diagnostic, LabeledSpan, MietteError, MietteSpanContents, Severity, SourceCode, SourceSpan,
    SpanContents,
};
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

/// A location: a byte span in one loaded file, reached through one Include chain.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Loc {
    /// Index into [`SourceMap::files`].
    pub file: u32,
    /// Index into the Include chains; 0 is the top-level file (no Include).
    pub chain: u32,
    pub start: u32,
    pub end: u32,
}

impl Loc {
    /// The span from the start of `self` to the end of `other` (same file), else `self`.
    pub fn to(self, other: Loc) -> Loc {
        if self.file == other.file && other.end >= self.start {
            Loc {
                end: other.end,
                ..self
            }
        } else {
            self
        }
    }
}

/// One loaded file.
#[derive(Debug)]
pub struct SourceFile {
    /// The path the file was read from (or that names an in-memory text).
    pub path: PathBuf,
    /// The name shown in diagnostics.
    pub name: String,
    pub text: Arc<str>,
    line_starts: OnceLock<Arc<Vec<u32>>>,
}

impl SourceFile {
    fn line_starts(&self) -> Arc<Vec<u32>> {
        self.line_starts
            .get_or_init(|| Arc::new(line_starts(&self.text)))
            .clone()
    }
}

fn line_starts(text: &str) -> Vec<u32> {
    let mut starts = vec![0u32];
    starts.extend(
        text.bytes()
            .enumerate()
            .filter(|&(_, b)| b == b'\n')
            .map(|(i, _)| i as u32 + 1),
    );
    starts
}

#[derive(Clone, Copy, Debug)]
struct Chain {
    parent: u32,
    /// The `Include` directive that opened this level.
    include: Loc,
}

/// All loaded files and Include chains of one scene.
#[derive(Debug, Default)]
pub struct SourceMap {
    pub files: Vec<SourceFile>,
    chains: Vec<Chain>,
}

impl SourceMap {
    pub fn new() -> SourceMap {
        SourceMap {
            files: Vec::new(),
            // Chain 0 is the top level; its own fields are never read.
            chains: vec![Chain {
                parent: 0,
                include: Loc::default(),
            }],
        }
    }

    /// Adds a file and returns its id.
    pub fn add_file(&mut self, path: &Path, text: Arc<str>) -> u32 {
        self.files.push(SourceFile {
            path: path.to_path_buf(),
            name: path.display().to_string(),
            text,
            line_starts: OnceLock::new(),
        });
        (self.files.len() - 1) as u32
    }

    /// A new Include level below `include.chain`, opened by the Include at `include`.
    pub fn push_chain(&mut self, include: Loc) -> u32 {
        self.chains.push(Chain {
            parent: include.chain,
            include,
        });
        (self.chains.len() - 1) as u32
    }

    pub fn text(&self, loc: Loc) -> &str {
        let text = &self.files[loc.file as usize].text;
        text.get(loc.start as usize..loc.end as usize).unwrap_or("")
    }

    /// The Include locations of `chain`, innermost first.
    pub fn include_stack(&self, mut chain: u32) -> Vec<Loc> {
        let mut out = Vec::new();
        while chain != 0 && (chain as usize) < self.chains.len() {
            let c = self.chains[chain as usize];
            out.push(c.include);
            chain = c.parent;
        }
        out
    }

    /// The files of the Include chain (innermost first), for cycle detection.
    pub fn chain_files(&self, chain: u32) -> Vec<u32> {
        self.include_stack(chain).iter().map(|l| l.file).collect()
    }

    /// 1-based line and column (in bytes) of a byte offset.
    pub fn line_col(&self, file: u32, offset: u32) -> (usize, usize) {
        let starts = self.files[file as usize].line_starts();
        let line = starts.partition_point(|&s| s <= offset).saturating_sub(1);
        (line + 1, (offset - starts[line]) as usize + 1)
    }

    /// `FILE:LINE:COL` of the start of `loc`.
    pub fn position(&self, loc: Loc) -> String {
        let (line, col) = self.line_col(loc.file, loc.start);
        format!("{}:{}:{}", self.files[loc.file as usize].name, line, col)
    }

    /// Builds a located diagnostic.
    pub fn report(
        &self,
        severity: Severity,
        loc: Loc,
        message: impl Into<String>,
        label: impl Into<String>,
        help: Option<String>,
    ) -> miette::Report {
        let file = &self.files[loc.file as usize];
        let len = file.text.len() as u32;
        let start = loc.start.min(len);
        // Long labels (a whole value list) are cut to their beginning.
        let mut end = loc.end.clamp(start, len).min(start.saturating_add(80));
        while !file.text.is_char_boundary(end as usize) {
            end -= 1;
        }
        let mut notes: Vec<String> = self
            .include_stack(loc.chain)
            .into_iter()
            .map(|inc| format!("included from {}", self.position(inc)))
            .collect();
        if let Some(h) = help {
            notes.insert(0, h);
        }
        miette::Report::new(LocatedDiagnostic {
            message: format!("{}: {}", self.position(loc), message.into()),
            severity,
            label: label.into(),
            span: SourceSpan::new((start as usize).into(), (end - start) as usize),
            source: Window {
                name: file.name.clone(),
                text: file.text.clone(),
                line_starts: file.line_starts(),
            },
            help: if notes.is_empty() {
                None
            } else {
                Some(notes.join("\n"))
            },
        })
    }
}

/// A diagnostic at one place in one file.
#[derive(Debug)]
pub struct LocatedDiagnostic {
    message: String,
    severity: Severity,
    label: String,
    span: SourceSpan,
    source: Window,
    help: Option<String>,
}

impl LocatedDiagnostic {
    /// The same diagnostic as an error (`--strict` makes warnings errors).
    pub fn as_error(&self, why: &str) -> LocatedDiagnostic {
        LocatedDiagnostic {
            message: format!("{} ({why})", self.message),
            severity: Severity::Error,
            label: self.label.clone(),
            span: self.span,
            source: self.source.clone(),
            help: self.help.clone(),
        }
    }
}

impl fmt::Display for LocatedDiagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for LocatedDiagnostic {}

impl Diagnostic for LocatedDiagnostic {
    fn severity(&self) -> Option<Severity> {
        Some(self.severity)
    }
    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.help
            .as_ref()
            .map(|h| Box::new(h) as Box<dyn fmt::Display>)
    }
    fn source_code(&self) -> Option<&dyn SourceCode> {
        Some(&self.source)
    }
    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        let label = if self.label.is_empty() {
            None
        } else {
            Some(self.label.clone())
        };
        Some(Box::new(std::iter::once(
            LabeledSpan::new_primary_with_span(label, self.span),
        )))
    }
}

/// Source code for miette that finds lines with an index (no rescan of big files)
/// and shows at most a window of a very long line.
#[derive(Debug, Clone)]
struct Window {
    name: String,
    text: Arc<str>,
    line_starts: Arc<Vec<u32>>,
}

const MAX_SNIPPET: usize = 160;

impl SourceCode for Window {
    fn read_span<'a>(
        &'a self,
        span: &SourceSpan,
        before: usize,
        after: usize,
    ) -> Result<Box<dyn SpanContents<'a> + 'a>, MietteError> {
        let text = self.text.as_bytes();
        let (s, e) = (span.offset(), span.offset() + span.len());
        if e > text.len() {
            return Err(MietteError::OutOfBounds);
        }
        let starts = &self.line_starts;
        let line_of = |off: usize| {
            starts
                .partition_point(|&st| st as usize <= off)
                .saturating_sub(1)
        };
        let (l0, l1) = (line_of(s), line_of(e.saturating_sub(1).max(s)));
        let first = l0.saturating_sub(before);
        let last = (l1 + after).min(starts.len() - 1);
        let mut ws = starts[first] as usize;
        let mut we = starts
            .get(last + 1)
            .map(|&x| x as usize)
            .unwrap_or(text.len());
        while we > ws && matches!(text[we - 1], b'\n' | b'\r') {
            we -= 1;
        }
        we = we.max(e);
        // Keep a window of a long line around the span.
        if s - ws > MAX_SNIPPET {
            ws = s - MAX_SNIPPET / 2;
        }
        if we - e > MAX_SNIPPET {
            we = e + MAX_SNIPPET / 2;
        }
        while ws > 0 && !self.text.is_char_boundary(ws) {
            ws -= 1;
        }
        while we < text.len() && !self.text.is_char_boundary(we) {
            we += 1;
        }
        let column = if before == 0 {
            s - starts[l0] as usize
        } else {
            0
        };
        let line = if before == 0 { l0 } else { first };
        Ok(Box::new(MietteSpanContents::new_named(
            self.name.clone(),
            &text[ws..we],
            SourceSpan::new(ws.into(), we - ws),
            line,
            column,
            last - first + 1,
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_and_reports() {
        let mut sm = SourceMap::new();
        let f = sm.add_file(
            Path::new("a.pbrt"),
            Arc::from("WorldBegin\n  Shape \"x\"\n"),
        );
        let loc = Loc {
            file: f,
            chain: 0,
            start: 13,
            end: 18,
        };
        assert_eq!(sm.line_col(f, 13), (2, 3));
        assert_eq!(sm.position(loc), "a.pbrt:2:3");
        let r = sm.report(Severity::Error, loc, "bad", "here", None);
        assert!(r.to_string().starts_with("a.pbrt:2:3: bad"));
    }
}
