//! The one parameter set every subcommand shares (seed 001 §2.1–2.4), with its validation.
//!
//! Validation guarantees that every intermediate value of the golden model fits an `i128`
//! (the integer type the model computes in), so the model never has to check for overflow.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// The edge shift E: forced, or chosen per scene (seed 003).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EdgeShift {
    Auto,
    Fixed(u32),
}

impl FromStr for EdgeShift {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        if s.eq_ignore_ascii_case("auto") {
            return Ok(EdgeShift::Auto);
        }
        s.parse::<u32>()
            .map(EdgeShift::Fixed)
            .map_err(|_| format!("'{s}' is neither 'auto' nor a non-negative integer"))
    }
}

impl fmt::Display for EdgeShift {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EdgeShift::Auto => write!(f, "auto"),
            EdgeShift::Fixed(e) => write!(f, "{e}"),
        }
    }
}

/// How the BIH builder chooses an inner node's split plane (`--tree`; `scene::bih`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TreeSplit {
    /// The thesis's: halve the split box on its longest axis (DECISIONS.md 11).
    Middle,
    /// Binned surface-area heuristic over the traversal's clipped boxes (DECISIONS.md 72): the
    /// default, by measurement.
    #[default]
    Sah,
}

impl TreeSplit {
    pub const ALL: [TreeSplit; 2] = [TreeSplit::Middle, TreeSplit::Sah];

    pub fn is_middle(&self) -> bool {
        *self == TreeSplit::Middle
    }

    /// A JSON file without the field: written before the option existed, so middle-split.
    pub fn absent() -> TreeSplit {
        TreeSplit::Middle
    }
}

impl FromStr for TreeSplit {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "middle" => Ok(TreeSplit::Middle),
            "sah" => Ok(TreeSplit::Sah),
            _ => Err(format!("'{s}' is not a split: use middle or sah")),
        }
    }
}

impl fmt::Display for TreeSplit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            TreeSplit::Middle => "middle",
            TreeSplit::Sah => "sah",
        })
    }
}

#[derive(Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Params {
    /// Bits of the vertex grid: the scene's longest side maps to 2^n − 1.
    pub n: u32,
    /// Bits of signed fixed-point vectors in [−1, 1] (normals, edges, directions); F = m − 1.
    pub m: u32,
    /// Edge shift: edge components are clamped to (−2^−E, 2^−E).
    pub edge_shift: EdgeShift,
    /// Division precision drop: numerator and denominator lose their T low bits.
    pub t: u32,
    /// Extra bits of the reciprocal ray direction used in BIH traversal (m + C bits).
    pub c: u32,
    /// A BIH node with at most this many triangles becomes a leaf.
    pub leaf_size: u32,
    /// Entries of the hardware traversal stack; bounds the BIH depth.
    pub stack_depth: u32,
    /// How the BIH chooses its split planes (default SAH, chosen by measurement: DECISIONS 72).
    /// Absent from JSON when `middle`, so files written before the option existed (all of
    /// them middle-split) read back as they were.
    #[serde(default = "TreeSplit::absent", skip_serializing_if = "TreeSplit::is_middle")]
    pub tree: TreeSplit,
    /// With the SAH: 0, or the price of a node step in hundredths of a triangle test, by which
    /// a node within the leaf size is split further when the SAH prices the split below the
    /// leaf (`scene::bih`; DECISIONS 139). Absent from JSON when 0, so older files read back.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub sah_step_percent: u32,
}

fn is_zero(x: &u32) -> bool {
    *x == 0
}

/// As derived, but without `sah_step_percent` when it is 0: the scene's hash, and so every
/// scene tag in a module name, reads this text (`SceneRoms::hash`), and an unpriced tree's
/// cores keep the names (and `generated/measured`'s netlist hashes) they had before the field.
impl fmt::Debug for Params {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut d = f.debug_struct("Params");
        d.field("n", &self.n)
            .field("m", &self.m)
            .field("edge_shift", &self.edge_shift)
            .field("t", &self.t)
            .field("c", &self.c)
            .field("leaf_size", &self.leaf_size)
            .field("stack_depth", &self.stack_depth)
            .field("tree", &self.tree);
        if self.sah_step_percent != 0 {
            d.field("sah_step_percent", &self.sah_step_percent);
        }
        d.finish()
    }
}

impl Default for Params {
    fn default() -> Self {
        Params {
            n: 29,
            m: 32,
            edge_shift: EdgeShift::Auto,
            t: 0,
            c: 16,
            leaf_size: 4,
            stack_depth: 32,
            tree: TreeSplit::Sah,
            sah_step_percent: 0,
        }
    }
}

/// Largest magnitude, in bits, any intermediate may reach (i128 keeps one bit for the sign).
const MODEL_BITS: u32 = 126;

/// The documented range of every parameter, used by validation and by `--help`.
pub const RANGES: &[(&str, u32, u32)] = &[
    ("n", 4, 40),
    ("m", 8, 64),
    ("t", 0, 62),
    ("c", 0, 64),
    ("edge-shift", 0, 120),
    ("leaf-size", 1, 64),
    ("stack-depth", 1, 256),
    ("sah-step-percent", 0, 10_000),
];

fn check_range(name: &str, value: u32) -> Result<()> {
    let (_, lo, hi) = RANGES.iter().find(|r| r.0 == name).copied().expect("known parameter");
    if value < lo || value > hi {
        return Err(Error::param(name, format!("{value} is out of range: must be {lo}..={hi}")));
    }
    Ok(())
}

impl Params {
    /// Fraction bits of an m-bit fixed-point value in [−1, 1].
    pub fn f(&self) -> u32 {
        self.m - 1
    }

    /// The largest edge shift E for this n and m: edge quantisation shifts an edge
    /// |Δx| < 2^n left by E + F, so n + 1 + E + F must fit the model's 126 bits (beyond, the
    /// shift wraps and the stored edges are garbage). `auto` stays within it; a fixed
    /// `--edge-shift` above it is refused by `validate`.
    pub fn max_edge_shift(&self) -> u32 {
        120u32.min(MODEL_BITS.saturating_sub(self.n + 1 + self.f()))
    }

    /// Checks every range and every cross-parameter limit; the message names the parameter,
    /// the value and the limit.
    pub fn validate(&self) -> Result<()> {
        check_range("n", self.n)?;
        check_range("m", self.m)?;
        check_range("t", self.t)?;
        check_range("c", self.c)?;
        check_range("leaf-size", self.leaf_size)?;
        check_range("stack-depth", self.stack_depth)?;
        check_range("sah-step-percent", self.sah_step_percent)?;
        if self.sah_step_percent > 0 && self.tree != TreeSplit::Sah {
            return Err(Error::param(
                "sah-step-percent",
                format!("{} prices the SAH's splits; --tree {} has none", self.sah_step_percent, self.tree),
            ));
        }
        if let EdgeShift::Fixed(e) = self.edge_shift {
            check_range("edge-shift", e)?;
        }
        let f = self.f();
        // Quantising np = n_p / n_r needs n_p · 2^F with |n_p| < 2^(2n+1).
        if 2 * self.n + 1 + f > MODEL_BITS {
            return Err(Error::param(
                "m",
                format!(
                    "{} with --n {} needs 2n+m = {} bits; the limit is {}",
                    self.m,
                    self.n,
                    2 * self.n + self.m,
                    MODEL_BITS
                ),
            ));
        }
        // BIH plane distance: (P − O) · inv with n+1 and m+C bits.
        if self.n + 1 + self.m + self.c > MODEL_BITS {
            return Err(Error::param(
                "c",
                format!(
                    "{} with --n {} --m {} needs n+m+C+1 = {} bits; the limit is {}",
                    self.c,
                    self.n,
                    self.m,
                    self.n + self.m + self.c + 1,
                    MODEL_BITS
                ),
            ));
        }
        // The denominator has m+2 bits; dropping T ≥ m−1 of them leaves nothing to divide by.
        if self.t > self.m - 2 {
            return Err(Error::param("t", format!("{} must be at most m−2 = {}", self.t, self.m - 2)));
        }
        if let EdgeShift::Fixed(e) = self.edge_shift {
            let max = self.max_edge_shift();
            if e > max {
                return Err(Error::param(
                    "edge-shift",
                    format!(
                        "{e} is above {max}, the largest E for --n {} --m {}: edge quantisation needs \
                         n + 1 + E + F = {} bits; the limit is {MODEL_BITS}",
                        self.n,
                        self.m,
                        self.n + 1 + e + self.f()
                    ),
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_thesis_values_and_valid() {
        let p = Params::default();
        assert_eq!((p.n, p.m, p.t, p.c), (29, 32, 0, 16));
        p.validate().unwrap();
    }

    #[test]
    fn out_of_range_names_parameter_value_and_limit() {
        let p = Params { n: 41, ..Params::default() };
        let e = p.validate().unwrap_err();
        assert_eq!(e.to_string(), "--n: 41 is out of range: must be 4..=40");
        let p = Params { t: 31, ..Params::default() };
        assert!(p.validate().unwrap_err().to_string().starts_with("--t: 31"));
        let p = Params { n: 40, m: 64, ..Params::default() };
        assert!(p.validate().unwrap_err().to_string().starts_with("--m: 64"));
    }

    /// E beyond n + 1 + E + F ≤ 126 made edge quantisation's shift wrap (120 passed for n 29,
    /// m 32, and `scene` reported no clamped triangle for garbage edges).
    #[test]
    fn edge_shift_above_the_width_limit_is_refused() {
        let at = |n, m, e| Params { n, m, edge_shift: EdgeShift::Fixed(e), ..Params::default() };
        assert_eq!(at(29, 32, 0).max_edge_shift(), 65);
        at(29, 32, 65).validate().unwrap();
        let e = at(29, 32, 66).validate().unwrap_err().to_string();
        assert!(e.starts_with("--edge-shift: 66 is above 65, the largest E for --n 29 --m 32"), "{e}");
        assert!(at(29, 32, 120).validate().is_err());
        // The smallest widths allow the whole documented range but for its top.
        assert_eq!(at(4, 8, 0).max_edge_shift(), 114);
        at(4, 8, 114).validate().unwrap();
        assert!(at(4, 8, 115).validate().is_err());
        // Every valid set's largest E is valid.
        for n in 4..=40 {
            for m in 8..=64 {
                let p = Params { n, m, t: 0, c: 0, ..Params::default() };
                if p.validate().is_ok() {
                    at(n, m, p.max_edge_shift()).validate().unwrap();
                }
            }
        }
    }

    #[test]
    fn edge_shift_parses() {
        assert_eq!("auto".parse::<EdgeShift>().unwrap(), EdgeShift::Auto);
        assert_eq!("10".parse::<EdgeShift>().unwrap(), EdgeShift::Fixed(10));
        assert!("-3".parse::<EdgeShift>().is_err());
    }

    #[test]
    fn tree_parses_and_the_default_is_not_serialised() {
        assert_eq!("middle".parse::<TreeSplit>().unwrap(), TreeSplit::Middle);
        assert_eq!("SAH".parse::<TreeSplit>().unwrap(), TreeSplit::Sah);
        assert!("median".parse::<TreeSplit>().is_err());
        let middle = Params { tree: TreeSplit::Middle, ..Params::default() };
        let d = serde_json::to_string(&middle).unwrap();
        assert!(!d.contains("tree"), "{d}");
        assert_eq!(serde_json::from_str::<Params>(&d).unwrap(), middle);
        let j = serde_json::to_string(&Params::default()).unwrap();
        assert!(j.ends_with(r#""tree":"sah"}"#), "{j}");
        assert_eq!(serde_json::from_str::<Params>(&j).unwrap(), Params::default());
    }
}
