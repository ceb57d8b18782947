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

use crate::rtl::{BinOp, Module, Sig, Ty, UnOp};

pub struct DividerOut {
    /// floor(|num| / |den|), n + 1 bits unsigned.
    pub t: Sig,
    /// 1 when t is a valid distance (no error).
    pub ok: Sig,
}

/// Latency in clock cycles of `divider_stages` for grid bits `n` and `bits_per_stage`
/// quotient bits computed between two registers.
pub fn latency(n: u32, bits_per_stage: u32) -> u32 {
    1 + (n + 1).div_ceil(bits_per_stage)
}

/// Appends the divider to `m`. `num` and `den` are signed. `bits_per_stage` quotient bits (1 or 2) are computed between two pipeline registers: 2
/// halves the registers and the latency at the price of two subtractors in series.
fn divider_stages(m: &mut Module, n: u32, bits_per_stage: u32, num: Sig, den: Sig) -> DividerOut {
    assert!((1..=2).contains(&bits_per_stage));
    assert!(num.ty.signed && den.ty.signed);
    let (wn, wd) = (num.ty.width, den.ty.width);
    let qbits = n + 1;
    // Stage 1: signs, zero tests, magnitudes (|x| of an s(w) value fits u(w)).
    let zero_n = m.konst("div_zero_n", num.ty, 0);
    let zero_d = m.konst("div_zero_d", den.ty, 0);
    let n_neg = m.bin("div_num_neg", BinOp::Lt, num, zero_n);
    let d_neg = m.bin("div_den_neg", BinOp::Lt, den, zero_d);
    let n_zero = m.bin("div_num_zero", BinOp::Eq, num, zero_n);
    let d_zero = m.bin("div_den_zero", BinOp::Eq, den, zero_d);
    let sign_diff = m.bin("div_sign_diff", BinOp::Xor, n_neg, d_neg);
    let e1 = m.bin("div_err_a", BinOp::Or, n_zero, d_zero);
    let err = m.bin("div_err_b", BinOp::Or, e1, sign_diff);
    let num_neg = m.un("div_num_negated", UnOp::Neg, num);
    let num_abs_s = m.mux("div_num_abs_s", n_neg, num_neg, num);
    let a = m.un("div_a", UnOp::AsUnsigned, num_abs_s);
    let den_neg = m.un("div_den_negated", UnOp::Neg, den);
    let den_abs_s = m.mux("div_den_abs_s", d_neg, den_neg, den);
    let b = m.un("div_b", UnOp::AsUnsigned, den_abs_s);
    let a_r = m.delay("div1_a", a);
    let b_r = m.delay("div1_b", b);
    let err_r = m.delay("div1_err", err);

    // The overflow test: hi = a >> (n+1) must be below b.
    let hi_w = wn.saturating_sub(qbits).max(1);
    let hi = if wn > qbits { m.slice("div_hi", a_r, qbits, wn - qbits) } else { m.konst("div_hi", Ty::u(1), 0) };
    let lo = m.resize("div_lo", a_r, qbits.min(wn));
    let lo = m.resize("div_lo_full", lo, qbits);
    let cw = hi_w.max(wd);
    let hi_c = m.resize("div_hi_c", hi, cw);
    let b_c = m.resize("div_b_c", b_r, cw);
    let overflow = m.bin("div_overflow", BinOp::Le, b_c, hi_c);
    let err2 = m.bin("div_err_c", BinOp::Or, err_r, overflow);
    // The partial remainder is < b whenever there is no overflow, so wd bits hold it.
    let p0 = m.resize("div_p0", hi, wd);

    // Quotient bits n … 0, one per stage; stage k consumes bit (n − k) of lo.
    let mut p = p0;
    let mut q = m.konst("div_q0", Ty::u(qbits), 0);
    let (mut b_s, mut lo_s, mut err_s) = (b_r, lo, err2);
    let b_w = m.resize("div_b_w", b_s, wd + 1);
    let mut b_w = b_w;
    for k in 0..qbits {
        let bit_ix = qbits - 1 - k;
        let bit = m.bit(&format!("div{k}_in"), lo_s, bit_ix);
        let p_w = m.resize(&format!("div{k}_pw"), p, wd + 1);
        let p2 = m.shl(&format!("div{k}_p2"), p_w, 1);
        let bit_w = m.resize(&format!("div{k}_bw"), bit, wd + 1);
        let p3 = m.bin(&format!("div{k}_p3"), BinOp::Or, p2, bit_w);
        let ge = m.bin(&format!("div{k}_ge"), BinOp::Le, b_w, p3);
        let diff = m.sub(&format!("div{k}_diff"), p3, b_w);
        let pn = m.mux(&format!("div{k}_pn"), ge, diff, p3);
        let pn = m.resize(&format!("div{k}_rem"), pn, wd);
        let q2 = m.shl(&format!("div{k}_q2"), q, 1);
        let ge_w = m.resize(&format!("div{k}_gew"), ge, qbits);
        let qn = m.bin(&format!("div{k}_qn"), BinOp::Or, q2, ge_w);
        if k + 1 == qbits {
            // Last stage: register the quotient and the result flag.
            let zero_q = m.konst("div_zero_q", Ty::u(qbits), 0);
            let q_zero = m.bin("div_q_zero", BinOp::Eq, qn, zero_q);
            let bad = m.bin("div_bad", BinOp::Or, err_s, q_zero);
            let one = m.konst("div_one", Ty::BIT, 1);
            let ok = m.bin("div_ok_c", BinOp::Xor, bad, one);
            let t = m.delay("div_t", qn);
            let ok = m.delay("div_ok", ok);
            return DividerOut { t, ok };
        }
        if (k + 1) % bits_per_stage != 0 {
            // The next quotient bit is computed in the same clock cycle.
            (p, q) = (pn, qn);
            continue;
        }
        p = m.delay(&format!("div{}_p", k + 2), pn);
        q = m.delay(&format!("div{}_q", k + 2), qn);
        b_s = m.delay(&format!("div{}_b", k + 2), b_s);
        b_w = m.resize(&format!("div{}_bw", k + 2), b_s, wd + 1);
        lo_s = m.delay(&format!("div{}_lo", k + 2), lo_s);
        err_s = m.delay(&format!("div{}_err", k + 2), err_s);
    }
    unreachable!("the loop returns at its last stage")
}

/// The divider as a standalone core: ports num, den → t, ok.
pub fn divider_core(n: u32, bits_per_stage: u32, num_width: u32, den_width: u32) -> Module {
    let suffix = if bits_per_stage == 2 { "_r4" } else { "" };
    let mut m = Module::new(&format!("fxrt_div_n{n}_a{num_width}_b{den_width}{suffix}"));
    let num = m.input("num", Ty::s(num_width));
    let den = m.input("den", Ty::s(den_width));
    let out = divider_stages(&mut m, n, bits_per_stage, num, den);
    m.output("t", out.t);
    m.output("ok", out.ok);
    m
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
