//! Spectrum files (`.spd`): the (wavelength nm, value) pairs a
//! `"spectrum name" "file.spd"` parameter names, in the text format pbrt-v3's
//! `ReadFloatFile` reads: numbers separated by white space, `#` to the end of
//! the line a comment.
//!
//! pbrt-v3 warns about text that is not a number and goes on with the numbers
//! it did read, and drops a last unpaired value with a warning; pbrs does the
//! same, one note per problem. Where pbrt-v3's reader is accidental, pbrs
//! reads what the file evidently means: a number at the very end of a file
//! without a final newline is kept (pbrt-v3 loses it), `E` exponents are
//! read like `e`, and `,` or `;` separate numbers as white space does (in
//! pbrt-v3 any character ends a number). `nan` and `inf` are not numbers.

/// What a spectrum file holds.
#[derive(Debug, Default, PartialEq)]
pub struct SpdFile {
    /// λ, value, λ, value, … in file order (an even count).
    pub pairs: Vec<f64>,
    /// Problems found, each one sentence for a warning.
    pub notes: Vec<String>,
}

/// At most this many "not a number" notes per file; the rest are counted.
const MAX_TEXT_NOTES: usize = 3;

/// Reads a spectrum file's text.
pub fn parse(text: &str) -> SpdFile {
    let mut values = Vec::new();
    let mut notes = Vec::new();
    let mut bad = 0usize;
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        for token in line.split(|c: char| c.is_whitespace() || c == ',' || c == ';') {
            if token.is_empty() {
                continue;
            }
            match token.parse::<f64>() {
                Ok(v) if v.is_finite() => values.push(v),
                _ => {
                    bad += 1;
                    if bad <= MAX_TEXT_NOTES {
                        notes.push(format!(
                            "line {}: \"{}\" is not a number: skipped (as pbrt-v3)",
                            i + 1,
                            shorten(token)
                        ));
                    }
                }
            }
        }
    }
    if bad > MAX_TEXT_NOTES {
        notes.push(format!(
            "{} more words that are not numbers: skipped",
            bad - MAX_TEXT_NOTES
        ));
    }
    if values.len() % 2 == 1 {
        notes.push(format!(
            "{} values, an odd count: the last one ({}) has no pair and is ignored (as pbrt-v3)",
            values.len(),
            values[values.len() - 1]
        ));
        values.pop();
    }
    notes.extend(shape_notes(&values));
    SpdFile {
        pairs: values,
        notes,
    }
}

/// Notes on pairs that are numbers but not a spectrum as measured: a
/// wavelength that is not positive, wavelengths out of increasing order
/// (pbrt-v3 sorts them silently; so does pbrs, with this note), negative
/// values (kept, as pbrt-v3).
fn shape_notes(pairs: &[f64]) -> Vec<String> {
    let mut notes = Vec::new();
    let lambdas: Vec<f64> = pairs.iter().step_by(2).copied().collect();
    if let Some(l) = lambdas.iter().find(|&&l| l <= 0.0) {
        notes.push(format!(
            "wavelength {l} nm is not positive (wavelengths are in nanometres)"
        ));
    }
    if let Some(i) = (1..lambdas.len()).find(|&i| lambdas[i] < lambdas[i - 1]) {
        notes.push(format!(
            "wavelengths are not in increasing order ({} nm after {} nm): the pairs are sorted (as pbrt-v3)",
            lambdas[i],
            lambdas[i - 1]
        ));
    }
    if let Some(v) = pairs.iter().skip(1).step_by(2).find(|&&v| v < 0.0) {
        notes.push(format!("value {v} is negative: kept (as pbrt-v3)"));
    }
    notes
}

fn shorten(s: &str) -> String {
    match s.char_indices().nth(24) {
        Some((i, _)) => format!("{}…", &s[..i]),
        None => s.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_comments_and_separators() {
        let f = parse("# measured\n400 0.5 # first\n 500\t0.25\r\n600,1E-1\n700 ; 2e0");
        assert_eq!(f.pairs, [400.0, 0.5, 500.0, 0.25, 600.0, 0.1, 700.0, 2.0]);
        assert!(f.notes.is_empty(), "{:?}", f.notes);
    }

    #[test]
    fn problems_are_noted_and_skipped() {
        let f = parse("400 0.5\n500 abc 0.25\n600 nan 1 inf 7");
        assert_eq!(f.pairs, [400.0, 0.5, 500.0, 0.25, 600.0, 1.0]);
        assert_eq!(f.notes.len(), 4, "{:?}", f.notes);
        assert!(f.notes[0].starts_with("line 2: \"abc\""), "{:?}", f.notes);
        assert!(f.notes[1].starts_with("line 3: \"nan\""), "{:?}", f.notes);
        assert!(f.notes[3].contains("the last one (7)"), "{:?}", f.notes);
        let many = parse(&"x ".repeat(10));
        assert!(many.pairs.is_empty());
        assert_eq!(many.notes.len(), MAX_TEXT_NOTES + 1);
        assert!(many.notes[MAX_TEXT_NOTES].starts_with("7 more"));
    }

    #[test]
    fn empty_and_long_words() {
        assert_eq!(parse(""), SpdFile::default());
        assert_eq!(parse("# nothing\n\n").pairs, Vec::<f64>::new());
        let f = parse(&"é".repeat(100));
        assert!(
            f.notes[0].contains(&format!("{}…", "é".repeat(24))),
            "{:?}",
            f.notes
        );
    }
}
