//! Parameter lists: `"type name" value` or `"type name" [ values… ]`, typed as
//! pbrt-v3 types them (parser.cpp:411-781, paramset.cpp).

use super::source::Loc;
use nom::bytes::complete::take_till1;
use nom::character::complete::{space0, space1};
use nom::combinator::all_consuming;
use nom::{IResult, Parser};
use std::cell::Cell;

/// A parameter type as pbrt-v3 names it. Aliases share a variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ParamType {
    Float,
    Integer,
    Bool,
    Point2,
    Vector2,
    Point3,
    Vector3,
    Normal,
    String,
    Texture,
    Rgb,
    Xyz,
    Blackbody,
    Spectrum,
}

/// Every type name pbrs accepts and its type (parser.cpp:437-474).
pub const TYPE_NAMES: &[(&str, ParamType)] = &[
    ("float", ParamType::Float),
    ("integer", ParamType::Integer),
    ("bool", ParamType::Bool),
    ("point2", ParamType::Point2),
    ("vector2", ParamType::Vector2),
    ("point3", ParamType::Point3),
    ("point", ParamType::Point3),
    ("vector3", ParamType::Vector3),
    ("vector", ParamType::Vector3),
    ("normal", ParamType::Normal),
    ("string", ParamType::String),
    ("texture", ParamType::Texture),
    ("rgb", ParamType::Rgb),
    ("color", ParamType::Rgb),
    ("xyz", ParamType::Xyz),
    ("blackbody", ParamType::Blackbody),
    ("spectrum", ParamType::Spectrum),
];

impl ParamType {
    pub fn from_name(s: &str) -> Option<ParamType> {
        TYPE_NAMES.iter().find(|(n, _)| *n == s).map(|&(_, t)| t)
    }

    /// Numbers per value (1 for scalars and strings).
    pub fn arity(self) -> usize {
        match self {
            ParamType::Point2 | ParamType::Vector2 | ParamType::Blackbody => 2,
            ParamType::Point3
            | ParamType::Vector3
            | ParamType::Normal
            | ParamType::Rgb
            | ParamType::Xyz => 3,
            _ => 1,
        }
    }

    /// Whether values are quoted strings (`string`, `texture`, `bool`).
    pub fn wants_strings(self) -> bool {
        matches!(
            self,
            ParamType::String | ParamType::Texture | ParamType::Bool
        )
    }

    /// Whether this is one of the spectrum types (one lookup category in pbrt-v3).
    pub fn is_spectrum(self) -> bool {
        matches!(
            self,
            ParamType::Rgb | ParamType::Xyz | ParamType::Blackbody | ParamType::Spectrum
        )
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    Nums(Vec<f64>),
    Strs(Vec<String>),
    Bools(Vec<bool>),
}

impl Values {
    pub fn len(&self) -> usize {
        match self {
            Values::Nums(v) => v.len(),
            Values::Strs(v) => v.len(),
            Values::Bools(v) => v.len(),
        }
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[derive(Debug)]
pub struct Param {
    pub ty: ParamType,
    /// The type as written (`color`, `point`, …), for messages.
    pub type_name: &'static str,
    pub name: String,
    pub values: Values,
    /// The `"type name"` string.
    pub loc: Loc,
    /// The values (from the first to the last token).
    pub values_loc: Loc,
    pub used: Cell<bool>,
}

impl Param {
    /// Number of values (a point3 counts once).
    pub fn count(&self) -> usize {
        self.values.len() / self.ty.arity()
    }
    pub fn nums(&self) -> &[f64] {
        match &self.values {
            Values::Nums(v) => v,
            _ => &[],
        }
    }
    pub fn strs(&self) -> &[String] {
        match &self.values {
            Values::Strs(v) => v,
            _ => &[],
        }
    }
    pub fn bools(&self) -> &[bool] {
        match &self.values {
            Values::Bools(v) => v,
            _ => &[],
        }
    }
}

/// A parameter list; a later item with the same name replaced an earlier one.
#[derive(Debug, Default)]
pub struct ParamList {
    pub items: Vec<Param>,
}

impl ParamList {
    /// Adds an item, replacing an earlier one of the same name (pbrt-v3's `Erase*`).
    pub fn push(&mut self, p: Param) {
        self.items.retain(|q| q.name != p.name);
        self.items.push(p);
    }

    pub fn get(&self, name: &str) -> Option<&Param> {
        self.items.iter().find(|p| p.name == name)
    }

    /// Finds `name` whose type satisfies `pred`, marking it used.
    pub fn find(&self, name: &str, pred: impl Fn(ParamType) -> bool) -> Option<&Param> {
        let p = self.items.iter().find(|p| p.name == name && pred(p.ty))?;
        p.used.set(true);
        Some(p)
    }

    pub fn mark_all_used(&self) {
        for p in &self.items {
            p.used.set(true);
        }
    }

    pub fn unused(&self) -> impl Iterator<Item = &Param> {
        self.items.iter().filter(|p| !p.used.get())
    }
}

/// Splits a declaration `"type name"` into its two words (nom).
pub fn split_declaration(decl: &str) -> IResult<&str, (&str, &str)> {
    let word = || take_till1(|c: char| c == ' ' || c == '\t');
    all_consuming((space0, word(), space1, word(), space0))
        .map(|(_, ty, _, name, _)| (ty, name))
        .parse(decl)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn declarations() {
        assert_eq!(
            split_declaration("float radius").unwrap().1,
            ("float", "radius")
        );
        assert_eq!(
            split_declaration("  color\tKd ").unwrap().1,
            ("color", "Kd")
        );
        assert!(split_declaration("radius").is_err());
        assert!(split_declaration("float a b").is_err());
        assert!(split_declaration("").is_err());
    }

    #[test]
    fn every_type_name() {
        for n in [
            "float",
            "integer",
            "bool",
            "point2",
            "vector2",
            "point3",
            "vector3",
            "point",
            "vector",
            "normal",
            "string",
            "texture",
            "rgb",
            "color",
            "xyz",
            "blackbody",
            "spectrum",
        ] {
            assert!(ParamType::from_name(n).is_some(), "{n}");
        }
        assert!(ParamType::from_name("normal3").is_none());
    }
}
