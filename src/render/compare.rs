//! Golden model against a float reference, pixel by pixel.

use super::Frame;
use serde::Serialize;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Disagreement {
    pub rays: u64,
    /// Golden hits where the reference misses.
    pub false_hits: u64,
    /// Golden misses where the reference hits.
    pub false_misses: u64,
    /// Both hit, but different triangles (often neighbours sharing an edge).
    pub other_triangle: u64,
}

impl Disagreement {
    pub fn hit_miss(&self) -> u64 {
        self.false_hits + self.false_misses
    }
    /// Hit/miss disagreements per ray.
    pub fn rate(&self) -> f64 {
        if self.rays == 0 { 0.0 } else { self.hit_miss() as f64 / self.rays as f64 }
    }
}

pub fn compare(golden: &Frame, reference: &Frame) -> Disagreement {
    let mut d = Disagreement { rays: golden.ids.len() as u64, ..Default::default() };
    for (&g, &r) in golden.ids.iter().zip(&reference.ids) {
        match (g >= 0, r >= 0) {
            (true, false) => d.false_hits += 1,
            (false, true) => d.false_misses += 1,
            (true, true) if g != r => d.other_triangle += 1,
            _ => {}
        }
    }
    d
}
