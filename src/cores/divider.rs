//! The specialised divider of seed 001 §3.2, pipelined: t = floor(|num| / |den|), only the
//! n + 1 quotient bits that can lie inside the box, with an error bit for everything that
//! cannot be a hit (zero operands, different signs, t < 1, t ≥ 2^(n+1)). The golden twin is
//! `Golden::divide`.
//!
//! Structure: a restoring long division whose partial remainder is only as wide as the
//! divisor. With a = |num| split as a = hi · 2^(n+1) + lo, the quotient fits n + 1 bits iff
//! hi < b (the overflow test), and each stage shifts in one bit of lo and subtracts b if it
//! can. Latency n + 2 (the thesis's divider: n + 3): one stage for the magnitudes and signs,
//! then n + 1 quotient stages; the first also makes the overflow test, the last also forms
//! the result flag. With two quotient bits per stage: 1 + ⌈(n + 1)/2⌉.

use crate::rtl::build::Builder;
use crate::rtl::pipeline::{Pipeline, Policy};
use crate::rtl::{Module, Ty};

/// Latency in clock cycles of `divider_stages` for grid bits `n` and `bits_per_stage`
/// quotient bits computed between two registers.
pub fn latency(n: u32, bits_per_stage: u32) -> u32 {
    1 + (n + 1).div_ceil(bits_per_stage)
}

crate::bundle! {
    /// Magnitudes of the operands and the error of their signs.
    struct Operands { a, b, err }
}
crate::bundle! {
    /// The partial remainder and the quotient bits so far.
    struct Partial { p, q }
}
crate::bundle! {
    /// The result ports.
    struct Quotient { t, ok }
}

/// The divider as a standalone core: ports num, den (signed) → t (n + 1 bits), ok.
/// `bits_per_stage` quotient bits (1 or 2) are computed between two pipeline registers: 2
/// halves the registers and the latency at the price of two subtractors in series — the same
/// description, with every other quotient stage merged by the pipeline policy.
pub fn divider_core(n: u32, bits_per_stage: u32, num_width: u32, den_width: u32) -> Module {
    assert!((1..=2).contains(&bits_per_stage));
    let suffix = if bits_per_stage == 2 { "_r4" } else { "" };
    let b = Builder::new(&format!("fxrt_div_n{n}_a{num_width}_b{den_width}{suffix}"));
    let (wn, wd) = (num_width, den_width);
    let num = b.input("num", Ty::s(wn));
    let den = b.input("den", Ty::s(wd));
    let qbits = n + 1;
    let merge = (0..qbits - 1).filter(|k| (k + 1) % bits_per_stage != 0).map(|k| format!("q{k}")).collect();
    let pipe = Pipeline::new(&b, Policy { merge });
    // Signs, zero tests, magnitudes (|x| of an s(w) value fits u(w)).
    let (n_neg, d_neg) = (num.lt(0).name("num_neg"), den.lt(0).name("den_neg"));
    let ops = pipe.stage(
        "operands",
        "signs, zero tests, magnitudes",
        Operands {
            a: n_neg.select(-num, num).unsigned(),
            b: d_neg.select(-den, den).unsigned(),
            err: num.eq(0) | den.eq(0) | (n_neg ^ d_neg),
        },
    );
    // The overflow test: hi = a >> (n+1) must be below b. Without overflow the partial
    // remainder stays below b, so wd bits hold it.
    let hi = if wn > qbits { ops.a.slice(qbits, wn - qbits) } else { b.konst(Ty::u(1), 0) };
    let lo = ops.a.resize(qbits.min(wn)).resize(qbits).name("lo");
    let cw = hi.width().max(wd);
    let err = (ops.err | ops.b.resize(cw).le(hi.resize(cw))).name("err");
    let mut part = Partial { p: hi.resize(wd), q: b.konst(Ty::u(qbits), 0) };
    let mut result = None;
    // Quotient bits n … 0; step k shifts in bit n − k of lo and subtracts b if it can.
    for k in 0..qbits {
        let bw = pipe.now(ops.b).resize(wd + 1);
        let p3 = (part.p.resize(wd + 1) << 1) | pipe.now(lo).bit(qbits - 1 - k).resize(wd + 1);
        // One subtraction: its sign is the comparison, so a stage is one carry chain and a
        // select rather than a comparator and a subtractor side by side.
        let diff = (p3.xsigned() - bw.xsigned()).name(&format!("diff{k}"));
        let ge = (!diff.msb()).name(&format!("ge{k}"));
        // Named, so timing reports name the stage (`rem7`, `quot7`).
        let p_next = ge.select(diff.slice(0, wd), p3.resize(wd)).name(&format!("rem{k}"));
        let q_next = ((part.q << 1) | ge.resize(qbits)).name(&format!("quot{k}"));
        if k + 1 < qbits {
            part = pipe.stage(&format!("q{k}"), "one quotient bit", Partial { p: p_next, q: q_next });
            continue;
        }
        let ok = !(pipe.now(err) | q_next.eq(0));
        result = Some(pipe.stage("result", "the quotient and its result flag", Quotient { t: q_next, ok }));
    }
    let out = result.expect("n + 1 ≥ 1 quotient bits");
    let lat = pipe.finish();
    assert_eq!(lat, latency(n, bits_per_stage), "latency formula and stages disagree");
    b.output("t", out.t);
    b.output("ok", out.ok);
    b.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtl::sim::Sim;
    use proptest::prelude::*;

    /// Golden::divide's semantics, restated for any widths.
    fn divide(n: u32, num: i128, den: i128) -> Option<i64> {
        if den == 0 || num == 0 || (num < 0) != (den < 0) {
            return None;
        }
        let (a, b) = (num.unsigned_abs(), den.unsigned_abs());
        if a < b || a >= b << (n + 1) {
            return None;
        }
        Some((a / b) as i64)
    }

    fn check(n: u32, wn: u32, wd: u32, cases: &[(i128, i128)]) {
        check_bps(n, 1, wn, wd, cases);
        check_bps(n, 2, wn, wd, cases);
    }

    fn check_bps(n: u32, bps: u32, wn: u32, wd: u32, cases: &[(i128, i128)]) {
        let m = divider_core(n, bps, wn, wd);
        let mut sim = Sim::new(&m);
        let (num, den) = (m.handle(m.inputs[0]), m.handle(m.inputs[1]));
        let (t, ok) = (m.handle(m.outputs[0].1), m.handle(m.outputs[1].1));
        let lat = latency(n, bps) as usize;
        let mut got = Vec::new();
        for i in 0..cases.len() + lat {
            let (a, b) = cases.get(i).copied().unwrap_or((0, 0));
            sim.set(num, a);
            sim.set(den, b);
            sim.tick();
            if i + 1 >= lat {
                got.push(if sim.get(ok) == 1 { Some(sim.get(t) as i64) } else { None });
            }
        }
        for (i, &(a, b)) in cases.iter().enumerate() {
            assert_eq!(got[i], divide(n, a, b), "n={n} bits/stage {bps}: {a}/{b}");
        }
    }

    #[test]
    fn exhaustive_small() {
        let mut cases = Vec::new();
        for a in -128i128..128 {
            for b in -32i128..32 {
                cases.push((a, b));
            }
        }
        check(3, 8, 6, &cases);
        check(6, 8, 6, &cases);
    }

    proptest! {
        #[test]
        fn wide_random(seed in prop::collection::vec((any::<i64>(), any::<i32>()), 200)) {
            // n = 29, 63-bit numerator, 34-bit denominator: the default pipeline's divider.
            let cases: Vec<(i128, i128)> = seed.iter().map(|&(a, b)| (a as i128 >> 1, (b as i128) << 1)).collect();
            check(29, 63, 34, &cases);
        }
    }
}
