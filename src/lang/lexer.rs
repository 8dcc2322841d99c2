//! The tokenizer: pbrt-v3's rules (parser.cpp:252-320) over bytes, no allocation
//! per token. A token is a kind and a byte span; its text is read from the file.

use super::source::Loc;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TokKind {
    /// A quoted string; the span includes the quotes. `escaped` if it holds `\`.
    Str {
        escaped: bool,
    },
    LBracket,
    RBracket,
    /// Anything else up to whitespace, `"`, `[` or `]`: a number, a directive name
    /// or an `ActiveTransform` word.
    Bare,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Token {
    pub kind: TokKind,
    pub loc: Loc,
}

/// A tokenizer error at a byte span.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LexError {
    pub start: u32,
    pub end: u32,
    pub message: String,
    pub label: &'static str,
}

/// Tokenizer over one file.
#[derive(Debug, Clone)]
pub struct Lexer {
    pub file: u32,
    pub chain: u32,
    pos: usize,
}

impl Lexer {
    pub fn new(file: u32, chain: u32) -> Lexer {
        Lexer {
            file,
            chain,
            pos: 0,
        }
    }

    /// The next token of `text` (the file this lexer reads), or `None` at its end.
    #[inline]
    pub fn next(&mut self, text: &[u8]) -> Option<Result<Token, LexError>> {
        let n = text.len();
        let mut i = self.pos;
        loop {
            while i < n && matches!(text[i], b' ' | b'\n' | b'\t' | b'\r') {
                i += 1;
            }
            if i < n && text[i] == b'#' {
                while i < n && text[i] != b'\n' {
                    i += 1;
                }
                continue;
            }
            break;
        }
        if i >= n {
            self.pos = n;
            return None;
        }
        let start = i;
        let kind = match text[i] {
            b'[' => {
                i += 1;
                TokKind::LBracket
            }
            b']' => {
                i += 1;
                TokKind::RBracket
            }
            b'"' => {
                i += 1;
                let mut escaped = false;
                loop {
                    if i >= n {
                        self.pos = n;
                        return Some(Err(LexError {
                            start: start as u32,
                            end: n as u32,
                            message: "unterminated string: the file ends inside it".into(),
                            label: "string starts here",
                        }));
                    }
                    match text[i] {
                        b'"' => {
                            i += 1;
                            break;
                        }
                        b'\n' => {
                            self.pos = i;
                            return Some(Err(LexError {
                                start: start as u32,
                                end: i as u32,
                                message: "unterminated string: a string must end on its line"
                                    .into(),
                                label: "string starts here",
                            }));
                        }
                        b'\\' => {
                            escaped = true;
                            let ok = i + 1 < n
                                && matches!(
                                    text[i + 1],
                                    b'b' | b'f' | b'n' | b'r' | b't' | b'\\' | b'\'' | b'"'
                                );
                            if !ok {
                                // Skip to the end of the line to resynchronise.
                                let bad = i;
                                while i < n && text[i] != b'\n' {
                                    i += 1;
                                }
                                self.pos = i;
                                return Some(Err(LexError {
                                    start: bad as u32,
                                    end: (bad + 2).min(n) as u32,
                                    message: "unknown escape sequence in a string (pbrt-v3 knows \\b \\f \\n \\r \\t \\\\ \\' \\\")".into(),
                                    label: "this escape",
                                }));
                            }
                            i += 2;
                        }
                        _ => i += 1,
                    }
                }
                TokKind::Str { escaped }
            }
            _ => {
                while i < n && !matches!(text[i], b' ' | b'\n' | b'\t' | b'\r' | b'"' | b'[' | b']')
                {
                    i += 1;
                }
                TokKind::Bare
            }
        };
        self.pos = i;
        Some(Ok(Token {
            kind,
            loc: Loc {
                file: self.file,
                chain: self.chain,
                start: start as u32,
                end: i as u32,
            },
        }))
    }
}

/// The contents of a string token (quotes removed, escapes resolved).
pub fn dequote(raw: &str, escaped: bool) -> String {
    let inner = &raw[1..raw.len() - 1];
    if !escaped {
        return inner.to_string();
    }
    let mut out = String::with_capacity(inner.len());
    let mut chars = inner.chars();
    while let Some(c) = chars.next() {
        if c == '\\' {
            match chars.next() {
                Some('b') => out.push('\u{8}'),
                Some('f') => out.push('\u{c}'),
                Some('n') => out.push('\n'),
                Some('r') => out.push('\r'),
                Some('t') => out.push('\t'),
                Some(o) => out.push(o),
                None => {}
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// Why a bare token is not a number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NumError {
    Malformed,
    NotFinite,
}

const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Parses a decimal number: `[+-]? (d+ (. d*)? | . d+) ([eE] [+-]? d+)?`.
/// No `inf`, `nan` or hex: pbrs refuses what would not be a finite number.
/// Short numbers take Clinger's exact fast path; the rest go to the standard
/// library's correctly rounded parser.
#[inline]
pub fn parse_number(b: &[u8]) -> Result<f64, NumError> {
    let n = b.len();
    let mut i = 0;
    let neg = match b.first() {
        Some(b'-') => {
            i += 1;
            true
        }
        Some(b'+') => {
            i += 1;
            false
        }
        _ => false,
    };
    let mut mant: u64 = 0;
    let mut digits = 0usize; // significant digits accumulated
    let mut any = false;
    let mut exp10: i64 = 0;
    let mut exact = true;
    while i < n && b[i].is_ascii_digit() {
        any = true;
        if mant == 0 && b[i] == b'0' {
        } else if digits < 19 {
            mant = mant * 10 + (b[i] - b'0') as u64;
            digits += 1;
        } else {
            exact = false;
            exp10 += 1;
        }
        i += 1;
    }
    if i < n && b[i] == b'.' {
        i += 1;
        while i < n && b[i].is_ascii_digit() {
            any = true;
            if mant == 0 && b[i] == b'0' {
                exp10 -= 1;
            } else if digits < 19 {
                mant = mant * 10 + (b[i] - b'0') as u64;
                digits += 1;
                exp10 -= 1;
            } else {
                exact = false;
            }
            i += 1;
        }
    }
    if !any {
        return Err(NumError::Malformed);
    }
    if i < n && (b[i] == b'e' || b[i] == b'E') {
        i += 1;
        let eneg = match b.get(i) {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        let mut e: i64 = 0;
        let mut edigits = false;
        while i < n && b[i].is_ascii_digit() {
            edigits = true;
            e = (e * 10 + (b[i] - b'0') as i64).min(1 << 40);
            i += 1;
        }
        if !edigits {
            return Err(NumError::Malformed);
        }
        exp10 += if eneg { -e } else { e };
    }
    if i != n {
        return Err(NumError::Malformed);
    }
    if mant == 0 {
        return Ok(if neg { -0.0 } else { 0.0 });
    }
    let v = if exact && mant < (1u64 << 53) && (-22..=22).contains(&exp10) {
        let m = mant as f64;
        if exp10 >= 0 {
            m * POW10[exp10 as usize]
        } else {
            m / POW10[(-exp10) as usize]
        }
    } else {
        // The grammar was checked above, so this is a plain decimal number.
        let s = std::str::from_utf8(&b[usize::from(neg || b[0] == b'+')..])
            .map_err(|_| NumError::Malformed)?;
        s.parse::<f64>().map_err(|_| NumError::Malformed)?
    };
    if !v.is_finite() {
        return Err(NumError::NotFinite);
    }
    Ok(if neg { -v } else { v })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lex(s: &str) -> Vec<(TokKind, String)> {
        let mut l = Lexer::new(0, 0);
        let mut out = Vec::new();
        while let Some(t) = l.next(s.as_bytes()) {
            let t = t.unwrap();
            out.push((
                t.kind,
                s[t.loc.start as usize..t.loc.end as usize].to_string(),
            ));
        }
        out
    }

    #[test]
    fn tokens() {
        let t = lex("Shape\"sphere\" # comment\n [1 -2.5]a#b");
        let texts: Vec<_> = t.iter().map(|x| x.1.as_str()).collect();
        assert_eq!(texts, ["Shape", "\"sphere\"", "[", "1", "-2.5", "]", "a#b"]);
        assert_eq!(t[1].0, TokKind::Str { escaped: false });
    }

    #[test]
    fn strings() {
        let mut l = Lexer::new(0, 0);
        assert!(l.next(b"\"abc\ndef\"").unwrap().is_err());
        let mut l = Lexer::new(0, 0);
        assert!(l.next(b"\"abc").unwrap().is_err());
        let mut l = Lexer::new(0, 0);
        assert!(l.next(b"\"a\\qb\"").unwrap().is_err());
        assert_eq!(dequote("\"a\\\"b\\n\"", true), "a\"b\n");
    }

    #[test]
    fn numbers() {
        for (s, v) in [
            ("1", 1.0),
            (".5", 0.5),
            ("1.", 1.0),
            ("-5e-51", -5e-51),
            ("+3", 3.0),
            ("0.000000001", 1e-9),
            ("1.74846e-007", 1.74846e-7),
            ("123456789012345678901234", 123456789012345678901234.0),
            ("0.1", 0.1),
            ("2.2250738585072014e-308", 2.2250738585072014e-308),
        ] {
            assert_eq!(parse_number(s.as_bytes()), Ok(v), "{s}");
        }
        for s in [
            "", "-", ".", "e5", "1e", "1.2.3", "nan", "inf", "0x10", "1,5", "--1",
        ] {
            assert_eq!(parse_number(s.as_bytes()), Err(NumError::Malformed), "{s}");
        }
        assert_eq!(parse_number(b"1e999"), Err(NumError::NotFinite));
    }

    #[test]
    fn numbers_match_std() {
        let mut x: u64 = 12345;
        for _ in 0..20000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = f64::from_bits(x);
            if !v.is_finite() {
                continue;
            }
            for s in [
                format!("{v}"),
                format!("{v:e}"),
                format!("{:.6}", (x % 100000) as f64 / 997.0),
            ] {
                assert_eq!(
                    parse_number(s.as_bytes()),
                    Ok(s.parse::<f64>().unwrap()),
                    "{s}"
                );
            }
        }
    }
}
