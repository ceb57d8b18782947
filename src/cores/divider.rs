//! The specialised divider of seed 001 §3.2, pipelined: t = floor(|num| / |den|), only the
//! n + 1 quotient bits that can lie inside the box, with an error bit for everything that
//! cannot be a hit (zero operands, different signs, t < 1, t ≥ 2^(n+1)). The golden twin is
//! `Golden::divide`.
//!
//! Structure: a **non-restoring** long division whose partial remainder is only one bit
//! wider than the divisor. With a = |num| split as a = hi · 2^(n+1) + lo, the quotient fits
//! n + 1 bits iff hi < b (the overflow test). The remainder r starts at hi and stays in
//! [−b, b); each step shifts in one bit of lo and subtracts b if r ≥ 0, adds it if r < 0. The
//! new sign gives the quotient bit (r' ≥ 0), and the same bits as a restoring division: the
//! restoring remainder is r when r ≥ 0 and r + b when r < 0, and in both cases r' is the
//! shifted restoring remainder minus b, whose sign is the restoring comparison
//! (docs/ARITHMETIC.md). A step is then one carry chain whose add-or-subtract is chosen by
//! the *registered* last quotient bit — `fxrt_addsub_w{W}`, which `fxrt synth --family ecp5`
//! maps to a CCU2C chain with the choice inside each cell's LUT (`fpga::ecp5::carry`), so a
//! quotient stage is a bare carry chain between registers (a restoring stage is a chain and a
//! select by its own carry-out, routed to every bit: 195 MHz at best on the ECP5, docs/TIMING.md).
//! Latency n + 2 (the thesis's divider: n + 3): one stage for the magnitudes and signs, then
//! n + 1 quotient stages; the first also makes the overflow test, the last also forms the
//! result flag. With two quotient bits per stage: 1 + ⌈(n + 1)/2⌉.
//!
//! **Separate ends** (`StageForm::SeparateEnds`, targets from `SEPARATE_ENDS_FROM_MHZ`): the
//! magnitudes take two stages (the negations, each one carry chain between registers, then
//! the select by the sign) and the result flag one of its own (its register sits by the
//! outputs, far from the last chain): two more cycles.

use crate::rtl::build::Builder;
use crate::rtl::pipeline::{Pipeline, Policy};
use crate::rtl::{Module, Ty};
use std::rc::Rc;

/// The lowest clock target (MHz) that gets the separate operand and result stages: the
/// divider with them merged measured 172 MHz on the ECP5 alone, but in the placed default core
/// its last chain into the result flag was a slowest path at 150 MHz (7.11 ns at seed 2).
pub const SEPARATE_ENDS_FROM_MHZ: u32 = 141;

/// Where the operand negations and the result flag go (module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StageForm {
    /// In the first and the last quotient stage.
    Plain,
    /// In stages of their own: two cycles more.
    SeparateEnds,
}

/// The file name prefix of the add-or-subtract step modules (`fpga::ecp5::carry`).
pub const ADDSUB_PREFIX: &str = "fxrt_addsub_w";

/// The divider's shape: quotient bits per pipeline stage and how a bit is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DividerShape {
    /// 1, or 2 for half the latency (two subtractions in series).
    pub bits_per_stage: u32,
    pub form: StageForm,
}

impl DividerShape {
    /// The shape a clock target gets.
    pub fn for_target(bits_per_stage: u32, target: crate::cores::clock::ClockTarget) -> DividerShape {
        let form = if target.splits(SEPARATE_ENDS_FROM_MHZ) { StageForm::SeparateEnds } else { StageForm::Plain };
        DividerShape { bits_per_stage, form }
    }

    pub fn plain(bits_per_stage: u32) -> DividerShape {
        DividerShape { bits_per_stage, form: StageForm::Plain }
    }

    /// Latency in clock cycles for grid bits `n`: the operand stage, the quotient stages
    /// and, with separate ends, the negations' stage and the result flag's.
    pub fn latency(self, n: u32) -> u32 {
        let extra = if self.form == StageForm::Plain { 0 } else { 2 };
        1 + extra + (n + 1).div_ceil(self.bits_per_stage)
    }

    fn suffix(self) -> String {
        let r4 = if self.bits_per_stage == 2 { "_r4" } else { "" };
        let form = if self.form == StageForm::SeparateEnds { "_se" } else { "" };
        format!("{r4}{form}")
    }
}

crate::bundle! {
    /// Magnitudes of the operands and the error of their signs.
    struct Operands { a, b, err }
}
crate::bundle! {
    /// Separate ends: the operands and their negations.
    struct Negated { num, den, neg_lo, neg_hi, lo_nz, hi_nz, neg_den, den_nz, sign_err }
}
crate::bundle! {
    /// The partial remainder r without its sign bit, `ge` = r ≥ 0 (the last quotient bit),
    /// the quotient bits so far, and whether those before the last are all 0.
    struct Partial { ge, r, q, zero }
}
crate::bundle! {
    /// The result ports.
    struct Quotient { t, ok }
}

/// The divider as a standalone core: ports num, den (signed) → t (n + 1 bits), ok.
/// With two quotient bits per stage every other quotient stage is merged by the pipeline
/// policy (the same description).
pub fn divider_core(n: u32, shape: DividerShape, num_width: u32, den_width: u32) -> Module {
    assert!((1..=2).contains(&shape.bits_per_stage));
    let b = Builder::new(&format!("fxrt_div_n{n}_a{num_width}_b{den_width}{}", shape.suffix()));
    divider_body(&b, n, shape, num_width, den_width);
    b.finish()
}

/// One non-restoring step as a module of `w`-bit operands: ports a, b (unsigned `w` bits),
/// sub → diff (the low w − 1 bits of a + b when !sub, a − b when sub, modulo 2^w) and ge (its
/// top bit inverted: the result is not negative). Written as a + (b ^ sub…sub) + sub: one
/// carry chain whose operand inversion a LUT in front of the chain makes (yosys) or each
/// chain cell's own LUT (`fpga::ecp5::carry`).
pub fn addsub_core(w: u32) -> Module {
    assert!(w >= 2, "a step of at least two bits");
    let b = Builder::new(&format!("{ADDSUB_PREFIX}{w}"));
    let (x, y, sub) = (b.input("a", Ty::u(w)), b.input("b", Ty::u(w)), b.input("sub", Ty::BIT));
    let mask = sub.signed().resize(w).unsigned().name("mask");
    let sum = (x + (y ^ mask) + sub.resize(w)).name("sum");
    b.output("diff", sum.slice(0, w - 1));
    b.output("ge", !sum.msb());
    b.finish()
}

fn divider_body<'b>(b: &'b Builder, n: u32, shape: DividerShape, wn: u32, wd: u32) {
    let form = shape.form;
    let num = b.input("num", Ty::s(wn));
    let den = b.input("den", Ty::s(wd));
    let qbits = n + 1;
    let merge = (0..qbits - 1).filter(|k| (k + 1) % shape.bits_per_stage != 0).map(|k| format!("q{k}")).collect();
    let pipe = Pipeline::new(b, Policy { merge });
    // Signs, zero tests, magnitudes (|x| of an s(w) value fits u(w)).
    let (n_neg, d_neg) = (num.lt(0).name("num_neg"), den.lt(0).name("den_neg"));
    let ops = if form == StageForm::Plain {
        let err = num.eq(0) | den.eq(0) | (n_neg ^ d_neg);
        let a = n_neg.select(-num, num).unsigned();
        pipe.stage(
            "operands",
            "signs, zero tests, magnitudes",
            Operands { a, b: d_neg.select(-den, den).unsigned(), err },
        )
    } else {
        // Each negation carry chains between registers, the select by the sign after them:
        // with the select behind the 63-bit chain the operand stage was the slowest. The
        // numerator's negation is cut where its quotient bits start (`lo`, the low
        // min(n + 1, wn − 1) bits): −num = (!hi + c) · 2^s + (!lo + 1) with the carry c = (lo
        // = 0), so both −hi and !hi are kept and the carry picks one in the next stage — two
        // chains side by side of at most max(s, wn − s) bits (a 63-bit chain made 219 MHz).
        let split = qbits.min(wn - 1);
        let (lo_x, hi_x) = (num.unsigned().slice(0, split), num.unsigned().slice(split, wn - split));
        // 0 − x, not !x + 1: yosys puts the inversion of a constant-free operand in a LUT before
        // the chain, and the subtrahend's inside it.
        let (neg_lo, neg_hi) = (lo_x.k(0) - lo_x, hi_x.k(0) - hi_x);
        let neg_den = (-den).unsigned();
        // The zero tests as ORs of bytes registered here and combined in the next stage: a
        // 63-bit test in one clock was the slowest path at 250 MHz (5.1 ns).
        // lo's bytes on their own: lo = 0 is also the negation's carry.
        let (lo_nz, hi_nz, den_nz, sign_err) =
            (lo_x.nonzero_bytes(), hi_x.nonzero_bytes(), den.nonzero_bytes(), n_neg ^ d_neg);
        let h = pipe.stage(
            "negations",
            "signs, zero tests by bytes, both operands negated",
            Negated { num, den, neg_lo, neg_hi, lo_nz, hi_nz, neg_den, den_nz, sign_err },
        );
        let lo_zero = h.lo_nz.eq(0).name("lo_zero");
        let err = (lo_zero & h.hi_nz.eq(0)) | h.den_nz.eq(0) | h.sign_err;
        let (lo, hi) = (h.num.unsigned().slice(0, split), h.num.unsigned().slice(split, wn - split));
        let neg = h.num.msb();
        let a = b.cat(&[neg.select(lo_zero.select(h.neg_hi, !hi), hi), neg.select(h.neg_lo, lo)]);
        let b_mag = h.den.msb().select(h.neg_den, h.den.unsigned());
        pipe.stage("operands", "magnitudes, zero tests", Operands { a, b: b_mag, err })
    };
    // The overflow test: hi = a >> (n+1) must be below b. Without overflow the partial
    // remainder stays below b, so wd bits hold it. b ≤ hi is hi − b ≥ 0, the `ge` of a step
    // module that subtracts (a chain whose top cell gives it on the ECP5: yosys maps `<=` to a
    // chain and a 6-input function, the sign of hi − b needs an inverter after the chain and
    // b + !hi one before it, 4.7–4.9 ns at 250 MHz), kept apart from the sign errors until the
    // result.
    let hi = if wn > qbits { ops.a.slice(qbits, wn - qbits) } else { b.konst(Ty::u(1), 0) };
    let lo = ops.a.resize(qbits.min(wn)).resize(qbits).name("lo");
    let cw = hi.width().max(wd) + 1;
    let test = Rc::new(addsub_core(cw));
    let overflow = b
        .instance("u_overflow", &test, &[hi.resize(cw), ops.b.resize(cw), b.konst(Ty::BIT, 1)])
        .get("ge")
        .name("overflow");
    let err = |pipe: &Pipeline<'b>| pipe.now(ops.err) | pipe.now(overflow);
    let one = b.konst(Ty::BIT, 1);
    let mut part = Partial { ge: one, r: hi.resize(wd), q: b.konst(Ty::u(qbits), 0), zero: one };
    let step = Rc::new(addsub_core(wd + 1));
    let mut result = None;
    // Quotient bits n … 0; step k shifts in bit n − k of lo and subtracts b if r ≥ 0, adds
    // it if not. r' lies in [−b, b), so wd + 1 bits of 2r + bit ∓ b are exact.
    for k in 0..qbits {
        let bw = pipe.now(ops.b).resize(wd + 1);
        let shifted = b.cat(&[part.r, pipe.now(lo).bit(qbits - 1 - k)]);
        let s = b.instance(&format!("u_step{k}"), &step, &[shifted, bw, part.ge]);
        // Named, so timing reports name the stage (`rem7`, `quot7`).
        let (r, ge) = (s.get("diff").name(&format!("rem{k}")), s.get("ge").name(&format!("ge{k}")));
        // Whether the quotient bits before this one are all 0, kept one bit at a time (from
        // the registered last bit) rather than tested over n + 1 bits at the end: that test
        // was three LUT levels before the result flag, 5.2 ns at 250 MHz.
        let q_was_zero = if k == 0 { one } else { (part.zero & !part.ge).name(&format!("zero{k}")) };
        let q_next = ((part.q << 1) | ge.resize(qbits)).name(&format!("quot{k}"));
        if k + 1 == qbits && form == StageForm::Plain {
            let ok = !(err(&pipe) | (q_was_zero & !ge));
            result = Some(pipe.stage("result", "the quotient and its result flag", Quotient { t: q_next, ok }));
            break;
        }
        part = pipe.stage(&format!("q{k}"), "one quotient bit", Partial { ge, r, q: q_next, zero: q_was_zero });
        if k + 1 == qbits {
            // The last quotient bit is registered beside its chain and the flag made in a
            // clock of its own: the flag's register sits by the outputs, far from the chain
            // (a 2.4 ns route measured at 250 MHz).
            let ok = !(err(&pipe) | (part.zero & !part.ge));
            result = Some(pipe.stage("result", "the result flag", Quotient { t: part.q, ok }));
        }
    }
    let out = result.expect("n + 1 ≥ 1 quotient bits");
    let lat = pipe.finish();
    assert_eq!(lat, shape.latency(n), "latency formula and stages disagree");
    b.output("t", out.t);
    b.output("ok", out.ok);
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
        use StageForm::*;
        for (bits_per_stage, form) in [(1, Plain), (2, Plain), (1, SeparateEnds), (2, SeparateEnds)] {
            check_shape(n, DividerShape { bits_per_stage, form }, wn, wd, cases);
        }
    }

    fn check_shape(n: u32, shape: DividerShape, wn: u32, wd: u32, cases: &[(i128, i128)]) {
        let m = divider_core(n, shape, wn, wd);
        let mut sim = Sim::new(&m);
        let (num, den) = (m.handle(m.inputs[0]), m.handle(m.inputs[1]));
        let (t, ok) = (m.handle(m.outputs[0].1), m.handle(m.outputs[1].1));
        let lat = shape.latency(n) as usize;
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
            assert_eq!(got[i], divide(n, a, b), "n={n} {shape:?}: {a}/{b}");
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
