//! Per set (parameters and core shape), over all scenes: what it gets wrong and what it costs;
//! the Pareto front.

use super::output::Results;
use super::{CoreShape, Set};
use crate::params::Params;

#[derive(Clone, Debug, PartialEq)]
pub struct SetSummary {
    pub params: Params,
    pub shape: CoreShape,
    /// Wrong pixels (against f64), summed over the scenes.
    pub wrong: u64,
    /// Pixels differing from the default-parameter image, summed over the scenes.
    pub diff: u64,
    pub rays: u64,
    /// DSP48E: from synthesis where it ran, else the estimate (the largest over the scenes).
    pub dsp48e: u64,
    pub dsp_from_synth: bool,
    pub isect_latency: u32,
    pub rom_bits: u64,
    /// Register bits of the netlist (the largest over the scenes).
    pub register_bits: u64,
}

/// One summary per parameter set that every scene evaluated completely, in plan order.
pub fn set_summaries(results: &Results) -> Vec<SetSummary> {
    let scenes = results.spec.scenes.len();
    let mut out: Vec<SetSummary> = Vec::new();
    for r in &results.rows {
        let (Some(q), Some(c), Some(dsp)) = (&r.quality, &r.cost, r.dsp48e(results.spec.xc5v_synth())) else {
            continue;
        };
        let s = match out.iter_mut().find(|s| s.set() == r.set()) {
            Some(s) => s,
            None => {
                out.push(SetSummary {
                    params: r.params,
                    shape: r.shape,
                    wrong: 0,
                    diff: 0,
                    rays: 0,
                    dsp48e: 0,
                    dsp_from_synth: results.spec.xc5v_synth(),
                    isect_latency: c.isect_latency,
                    rom_bits: 0,
                    register_bits: 0,
                });
                out.last_mut().expect("just pushed")
            }
        };
        s.wrong += q.wrong_pixels;
        s.diff += q.diff_vs_default;
        s.rays += q.rays;
        s.dsp48e = s.dsp48e.max(dsp);
        s.rom_bits += c.rom_bits;
        s.register_bits = s.register_bits.max(c.register_bits);
    }
    let complete = |s: &SetSummary| {
        results
            .rows
            .iter()
            .filter(|r| r.set() == s.set() && r.quality.is_some() && r.dsp48e(results.spec.xc5v_synth()).is_some())
            .count()
            == scenes
    };
    out.into_iter().filter(complete).collect()
}

impl SetSummary {
    pub fn set(&self) -> Set {
        Set { params: self.params, shape: self.shape }
    }
}

/// Indices of the sets no other set beats on both DSP48E and wrong pixels (ties: the first),
/// in order of rising DSP48E.
pub fn pareto_front(sets: &[SetSummary]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..sets.len()).collect();
    order.sort_by_key(|&i| (sets[i].dsp48e, sets[i].wrong, i));
    let mut front = Vec::new();
    let mut best = u64::MAX;
    for i in order {
        if sets[i].wrong < best {
            best = sets[i].wrong;
            front.push(i);
        }
    }
    front
}

/// The set with the fewest DSP48E (then register bits, ROM bits, latency) whose image equals
/// the default parameters' on every scene.
pub fn cheapest_same_image(sets: &[SetSummary]) -> Option<&SetSummary> {
    sets.iter().filter(|s| s.diff == 0).min_by_key(|s| (s.dsp48e, s.register_bits, s.rom_bits, s.isect_latency))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(dsp: u64, wrong: u64, diff: u64) -> SetSummary {
        SetSummary {
            params: Params::default(),
            shape: CoreShape::default(),
            wrong,
            diff,
            rays: 100,
            dsp48e: dsp,
            dsp_from_synth: false,
            isect_latency: 38,
            rom_bits: 10,
            register_bits: 4000,
        }
    }

    #[test]
    fn pareto_front_keeps_only_undominated_sets() {
        let sets = [set(44, 0, 0), set(20, 50, 9), set(30, 5, 2), set(30, 7, 2), set(50, 0, 0), set(10, 50, 9)];
        assert_eq!(pareto_front(&sets), vec![5, 2, 0]);
        assert_eq!(cheapest_same_image(&sets).unwrap().dsp48e, 44);
    }
}
