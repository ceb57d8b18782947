//! The frame checksum in hardware (twin: `model::checksum`): a result packed into 32-bit
//! words, mixed by one add-rotate-xor round per clock (a register after each round: one
//! 32-bit carry chain and two XORs per stage), one result per clock.

use crate::model::checksum::{FINAL_KEYS, ResultWidths, START};
use crate::rtl::Ty;
use crate::rtl::build::{Builder, S};

/// The result fields packed as `model::checksum::pack` packs them: hit, id, tri, t, u, v from
/// the least significant bit, the fields other than hit and id zero for a miss; 32-bit words.
pub fn pack<'b>(b: &'b Builder, w: &ResultWidths, hit: S<'b>, fields: [S<'b>; 5]) -> Vec<S<'b>> {
    let [id, tri, t, u, v] = fields;
    let zero_on_miss = |x: S<'b>| hit.select(x.unsigned(), x.unsigned().k(0));
    let pad = w.words() * 32 - w.bits();
    let mut parts: Vec<S<'b>> = Vec::new();
    if pad > 0 {
        parts.push(b.konst(Ty::u(pad), 0));
    }
    parts.extend([zero_on_miss(v), zero_on_miss(u), zero_on_miss(t), zero_on_miss(tri), id.unsigned(), hit]);
    let all = b.cat(&parts).name("mix_packed");
    (0..w.words()).map(|k| all.slice(32 * k, 32)).collect()
}

/// (valid, mix) `words.len() + FINAL_KEYS.len()` clocks after `valid` and `words`; `valid`
/// rides in registers `rst` clears.
pub fn mix_pipeline<'b>(b: &'b Builder, valid: S<'b>, words: &[S<'b>]) -> (S<'b>, S<'b>) {
    let u32t = Ty::u(32);
    let rotr8 = |x: S<'b>| b.cat(&[x.slice(0, 8), x.slice(8, 24)]);
    let rotl3 = |x: S<'b>| b.cat(&[x.slice(0, 29), x.slice(29, 3)]);
    let (mut x, mut y) = (b.konst(u32t, START.0 as i128), b.konst(u32t, START.1 as i128));
    let keys: Vec<S<'b>> = words
        .iter()
        .enumerate()
        .map(|(k, &w)| if k == 0 { w } else { b.delay_line(&format!("mix_key{k}"), w, k as u32) })
        .chain(FINAL_KEYS.iter().map(|&k| b.konst(u32t, k as i128)))
        .collect();
    for (k, &key) in keys.iter().enumerate() {
        let nx = ((rotr8(x) + y) ^ key).name(&format!("mix_x{k}_c"));
        let ny = (rotl3(y) ^ nx).name(&format!("mix_y{k}_c"));
        (x, y) = (b.delay(&format!("mix_x{k}"), nx), b.delay(&format!("mix_y{k}"), ny));
    }
    (b.valid_line("mix_valid", valid, keys.len() as u32), y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::checksum::{mix, pack as pack_model};
    use crate::model::golden::Hit;
    use crate::rtl::sim::Sim;

    /// Random results through the pipeline, one per clock: each mix equals the model's, the
    /// pipeline's length later.
    #[test]
    fn mixes_as_the_model_does() {
        let w = ResultWidths { id: 9, tri: 7, t: 20, u: 17, v: 17 };
        let b = Builder::new("mix_dut");
        let valid = b.input("valid", Ty::BIT);
        let hit = b.input("hit", Ty::BIT);
        let ins = [
            b.input("id", Ty::u(w.id)),
            b.input("tri", Ty::u(w.tri)),
            b.input("t", Ty::s(w.t)),
            b.input("u", Ty::s(w.u)),
            b.input("v", Ty::s(w.v)),
        ];
        let words = pack(&b, &w, hit, ins);
        let (mv, m) = mix_pipeline(&b, valid, &words);
        b.output("mv", mv);
        b.output("m", m);
        let module = b.finish();
        let mut sim = Sim::new(&module);
        let port = |k: usize| module.handle(module.inputs[k]);
        let (out_v, out_m) = (module.handle(module.outputs[0].1), module.handle(module.outputs[1].1));
        let mut rng = crate::rng::SplitMix64(3);
        let depth = w.words() as usize + FINAL_KEYS.len();
        let mut sent: Vec<Option<u32>> = Vec::new();
        for cycle in 0..200 {
            let r = |bits: u32, rng: &mut crate::rng::SplitMix64| (rng.next_u64() & ((1u64 << bits) - 1)) as i64;
            let signed = |bits: u32, rng: &mut crate::rng::SplitMix64| r(bits, rng) - (1i64 << (bits - 1));
            let valid = !rng.next_u64().is_multiple_of(3);
            let id = r(w.id, &mut rng) as u64;
            let hit = (!rng.next_u64().is_multiple_of(4)).then(|| Hit {
                tri: r(w.tri, &mut rng) as u32,
                t: signed(w.t, &mut rng),
                u: signed(w.u, &mut rng),
                v: signed(w.v, &mut rng),
            });
            // A miss's other fields are noise the mix must ignore.
            let h = hit.unwrap_or(Hit { tri: 5, t: -3, u: 7, v: 1 });
            for (k, x) in
                [valid as i128, hit.is_some() as i128, id as i128, h.tri as i128, h.t as i128, h.u as i128, h.v as i128]
                    .into_iter()
                    .enumerate()
            {
                sim.set(port(k), x);
            }
            sim.eval();
            if cycle >= depth {
                let want = sent[cycle - depth];
                assert_eq!(sim.get(out_v) == 1, want.is_some(), "cycle {cycle}");
                if let Some(want) = want {
                    assert_eq!(sim.get(out_m) as u32, want, "cycle {cycle}");
                }
            }
            sent.push(valid.then(|| mix(&pack_model(&w, id, hit))));
            sim.tick();
        }
    }
}
