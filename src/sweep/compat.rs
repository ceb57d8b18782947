//! How `SweepSpec`'s lists that were once single values read and write: `leaf_size` (a number
//! until the leaf size became an axis) and `slots` / `units` (numbers, absent at the
//! defaults). A list of one is written as that number and a number reads back as a list of one,
//! so a results.json written before reads back as the same spec and a sweep that does not
//! sweep them writes the same bytes as before.

use crate::cores::top::{DEFAULT_SLOTS, DEFAULT_UNITS};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// `#[serde(with = "one_or_many")]` for a `Vec<u32>`.
pub mod one_or_many {
    use super::*;

    pub fn serialize<S: Serializer>(v: &[u32], s: S) -> Result<S::Ok, S::Error> {
        match v {
            [one] => s.serialize_u32(*one),
            many => many.serialize(s),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<u32>, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum OneOrMany {
            One(u32),
            Many(Vec<u32>),
        }
        Ok(match OneOrMany::deserialize(d)? {
            OneOrMany::One(v) => vec![v],
            OneOrMany::Many(v) => v,
        })
    }
}

pub fn default_slots() -> Vec<u32> {
    vec![DEFAULT_SLOTS]
}

pub fn is_default_slots(k: &[u32]) -> bool {
    k == [DEFAULT_SLOTS]
}

pub fn default_units() -> Vec<u32> {
    vec![DEFAULT_UNITS]
}

pub fn is_default_units(u: &[u32]) -> bool {
    u == [DEFAULT_UNITS]
}

/// One intersection pipeline (`SweepSpec::pipelines`, `CoreShape::pipelines`), absent when so.
pub fn one_pipeline() -> u32 {
    1
}

pub fn is_one_pipeline(p: &u32) -> bool {
    *p == 1
}
