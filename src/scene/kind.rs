//! The one shape of every pluggable family (materials, textures, media,
//! lights, shapes, cameras, filters, samplers, integrators): a kind is a
//! pbrt-v3 type name, whether pbrs renders it, the parameters it reads
//! (names, types, pbrt-v3's defaults, a line of doc each), what it is, and
//! its builder. Each family keeps one table of kinds, which the loader
//! (parsing, "did you mean"), `--check`, `grammar/REFERENCE.md` and the
//! family's completeness test all read; the builder's type is the family's
//! own (`B`).

use super::ParamSpec;

/// Whether pbrs renders a kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Support {
    Supported,
    /// Known to pbrt-v3, not rendered by pbrs: the loader warns, giving the
    /// reason, and does what the family does for such kinds (a matte for
    /// materials, the stand-in the reason names for textures, nothing for
    /// lights).
    Unsupported(&'static str),
}

/// One kind of a family.
pub struct Kind<B: 'static> {
    /// pbrt-v3's type name.
    pub name: &'static str,
    /// Other names pbrt-v3 takes for the same kind (`lowdiscrepancy` for
    /// `02sequence`, `area` for `diffuse`).
    pub aliases: &'static [&'static str],
    pub support: Support,
    pub params: &'static [ParamSpec],
    /// What it is, for `grammar/REFERENCE.md` and `--check`.
    pub doc: &'static str,
    pub build: B,
}

impl<B> Kind<B> {
    /// True if `name` is this kind's name or one of its aliases.
    pub fn is(&self, name: &str) -> bool {
        self.name == name || self.aliases.contains(&name)
    }

    pub fn is_supported(&self) -> bool {
        self.support == Support::Supported
    }

    /// The reason pbrs does not render it, if it does not.
    pub fn unsupported(&self) -> Option<&'static str> {
        match self.support {
            Support::Supported => None,
            Support::Unsupported(why) => Some(why),
        }
    }

    /// The declared parameter `name`, if any.
    pub fn param(&self, name: &str) -> Option<&'static ParamSpec> {
        self.params.iter().find(|s| s.name == name)
    }
}

/// The kind of `table` called `name` (or one of its aliases).
pub fn find<B>(table: &'static [Kind<B>], name: &str) -> Option<&'static Kind<B>> {
    table.iter().find(|k| k.is(name))
}

/// Every name `table` takes, aliases included (for "did you mean").
pub fn names<B>(table: &'static [Kind<B>]) -> Vec<&'static str> {
    table
        .iter()
        .flat_map(|k| std::iter::once(k.name).chain(k.aliases.iter().copied()))
        .collect()
}

/// Where a kind's builder reports what pbrt-v3 would check about its
/// parameters: at the values of parameter `at` when the statement gave it,
/// else at the statement itself. The loader locates the message
/// (file:line:col, the snippet, the Include chain).
pub trait Report {
    fn warn(&mut self, at: Option<&str>, msg: String, label: &str);
    fn error(&mut self, at: Option<&str>, msg: String, label: &str);
}

/// A [`Report`] that keeps the messages (for building kinds outside a
/// scene file: tests, the command line's defaults).
#[derive(Default, Debug)]
pub struct Collected {
    pub warnings: Vec<String>,
    pub errors: Vec<String>,
}

impl Report for Collected {
    fn warn(&mut self, _: Option<&str>, msg: String, _: &str) {
        self.warnings.push(msg);
    }
    fn error(&mut self, _: Option<&str>, msg: String, _: &str) {
        self.errors.push(msg);
    }
}

/// The name of `names` closest to `word` (a case-insensitive edit distance
/// of at most a third of the name's length, and at least 2), for "did you
/// mean".
pub fn closest_name<'a>(word: &str, names: &[&'a str]) -> Option<&'a str> {
    let d = |a: &str, b: &str| strsim(a, b);
    names
        .iter()
        .map(|n| (*n, d(word, n)))
        .filter(|&(n, dist)| dist <= (n.chars().count() / 3).max(2))
        .min_by_key(|&(_, dist)| dist)
        .map(|(n, _)| n)
}

fn strsim(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.to_lowercase().chars().take(128).collect();
    let b: Vec<char> = b.to_lowercase().chars().take(128).collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut cur = vec![i; b.len() + 1];
        for j in 1..=b.len() {
            cur[j] = (prev[j - 1] + usize::from(a[i - 1] != b[j - 1]))
                .min(prev[j] + 1)
                .min(cur[j - 1] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}
