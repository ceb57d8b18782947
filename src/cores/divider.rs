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
//!
//! **Lookahead** (`StageForm::Lookahead`, targets from `LOOKAHEAD_FROM_MHZ`): a stage is then
//! one carry chain and one LUT. A plain stage ends with its sign selecting the next
//! remainder — the sign leaves the carry chain and is routed to every bit's mux, about a
//! third of the clock at 170 MHz. The lookahead stage keeps both candidates of the remainder
//! (`diff` if the last subtraction was taken, `p` if not) and the last sign in registers,
//! subtracts b from both in two chains side by side, and selects afterwards with the
//! *registered* sign, whose fan-out is routed while the chains settle. Twice the
//! subtractors, the same number of quotient stages. The magnitudes then take two stages (the
//! negations, then the select by the sign) and the result flag one of its own: two more
//! cycles.

use crate::rtl::build::{Builder, S};
use crate::rtl::pipeline::{Pipeline, Policy};
use crate::rtl::{Module, Ty};

/// The lowest clock target (MHz) that gets the lookahead stage: a plain stage measured
/// 172 MHz on the ECP5 (docs/TIMING.md).
pub const LOOKAHEAD_FROM_MHZ: u32 = 176;

/// How a quotient bit is built (module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StageForm {
    /// One subtraction, its sign selects the next remainder.
    Plain,
    /// Both candidate remainders subtracted, the registered sign selects.
    Lookahead,
}

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
        let form = if target.splits(LOOKAHEAD_FROM_MHZ) { StageForm::Lookahead } else { StageForm::Plain };
        DividerShape { bits_per_stage, form }
    }

    pub fn plain(bits_per_stage: u32) -> DividerShape {
        DividerShape { bits_per_stage, form: StageForm::Plain }
    }

    /// Latency in clock cycles for grid bits `n`: the operand stage, the quotient stages
    /// and, with lookahead, the negations' stage and the result flag's.
    pub fn latency(self, n: u32) -> u32 {
        let extra = if self.form == StageForm::Plain { 0 } else { 2 };
        1 + extra + (n + 1).div_ceil(self.bits_per_stage)
    }

    fn suffix(self) -> String {
        let r4 = if self.bits_per_stage == 2 { "_r4" } else { "" };
        let form = if self.form == StageForm::Lookahead { "_la" } else { "" };
        format!("{r4}{form}")
    }
}

crate::bundle! {
    /// Magnitudes of the operands and the error of their signs.
    struct Operands { a, b, err }
}
crate::bundle! {
    /// Lookahead: the operands and their negations.
    struct Negated { num, den, neg_num, neg_den, err }
}
crate::bundle! {
    /// The partial remainder and the quotient bits so far.
    struct Partial { p, q }
}
crate::bundle! {
    /// The remainder is `diff` if `ge` (the last subtraction was taken), else `p` (in the
    /// plain form always `p`).
    struct Candidates { ge, diff, p, q }
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

fn divider_body<'b>(b: &'b Builder, n: u32, shape: DividerShape, wn: u32, wd: u32) {
    let form = shape.form;
    let num = b.input("num", Ty::s(wn));
    let den = b.input("den", Ty::s(wd));
    let qbits = n + 1;
    let merge = (0..qbits - 1).filter(|k| (k + 1) % shape.bits_per_stage != 0).map(|k| format!("q{k}")).collect();
    let pipe = Pipeline::new(b, Policy { merge });
    // Signs, zero tests, magnitudes (|x| of an s(w) value fits u(w)).
    let (n_neg, d_neg) = (num.lt(0).name("num_neg"), den.lt(0).name("den_neg"));
    let err = num.eq(0) | den.eq(0) | (n_neg ^ d_neg);
    let ops = if form == StageForm::Plain {
        let a = n_neg.select(-num, num).unsigned();
        pipe.stage(
            "operands",
            "signs, zero tests, magnitudes",
            Operands { a, b: d_neg.select(-den, den).unsigned(), err },
        )
    } else {
        // Each negation one carry chain between registers, the select by the sign after
        // another: with the select behind the 63-bit chain the operand stage was the slowest.
        let (neg_num, neg_den) = ((-num).unsigned(), (-den).unsigned());
        let h = pipe.stage("negations", "signs, zero tests, both operands negated", Negated { num, den, neg_num, neg_den, err });
        let magnitude = |x: S<'b>, neg: S<'b>| -> S<'b> { x.msb().select(neg, x.unsigned()) };
        let (a, b_mag) = (magnitude(h.num, h.neg_num), magnitude(h.den, h.neg_den));
        pipe.stage("operands", "magnitudes", Operands { a, b: b_mag, err: h.err })
    };
    // The overflow test: hi = a >> (n+1) must be below b. Without overflow the partial
    // remainder stays below b, so wd bits hold it. b ≤ hi is the sign of hi − b (one carry
    // chain and its top bit; yosys maps `<=` to a chain and a 6-input function), kept apart
    // from the sign errors until the result.
    let hi = if wn > qbits { ops.a.slice(qbits, wn - qbits) } else { b.konst(Ty::u(1), 0) };
    let lo = ops.a.resize(qbits.min(wn)).resize(qbits).name("lo");
    let cw = hi.width().max(wd);
    let overflow = (!(hi.resize(cw).xsigned() - ops.b.resize(cw).xsigned()).msb()).name("overflow");
    let err = |pipe: &Pipeline<'b>| pipe.now(ops.err) | pipe.now(overflow);
    let mut part = Candidates {
        ge: b.konst(Ty::BIT, 0),
        diff: b.konst(Ty::u(wd), 0),
        p: hi.resize(wd),
        q: b.konst(Ty::u(qbits), 0),
    };
    let mut result = None;
    // Quotient bits n … 0; step k shifts in bit n − k of lo and subtracts b if it can.
    for k in 0..qbits {
        let bw = pipe.now(ops.b).resize(wd + 1);
        let bit = pipe.now(lo).bit(qbits - 1 - k).resize(wd + 1);
        let shifted = |r: S<'b>| -> S<'b> { (r.resize(wd + 1) << 1) | bit };
        // One subtraction per candidate: its sign is the comparison, so a stage is one carry
        // chain and a select rather than a comparator and a subtractor side by side.
        let subtract = |p3: S<'b>, tag: &str| -> (S<'b>, S<'b>) {
            let d = (p3.xsigned() - bw.xsigned()).name(&format!("diff{tag}{k}"));
            (d.slice(0, wd), (!d.msb()).name(&format!("ge{tag}{k}")))
        };
        let p3_k = shifted(part.p);
        let (d_k, ge_k) = subtract(p3_k, "k");
        // Lookahead from the second bit on: both candidates (taken, kept) are subtracted and
        // the registered sign selects.
        let (p3, diff, ge) = if form == StageForm::Lookahead && k > 0 {
            let p3_t = shifted(part.diff);
            let (d_t, ge_t) = subtract(p3_t, "t");
            let sel = |t: S<'b>, f: S<'b>| -> S<'b> { part.ge.select(t, f) };
            (sel(p3_t, p3_k), sel(d_t, d_k), sel(ge_t, ge_k))
        } else {
            (p3_k, d_k, ge_k)
        };
        // q = 0 afterwards iff it was 0 before and this bit is 0: the zero test of the last
        // plain stage then runs beside its chain instead of after it.
        let q_was_zero = part.q.eq(0);
        let q_next = ((part.q << 1) | ge.resize(qbits)).name(&format!("quot{k}"));
        if k + 1 == qbits && form == StageForm::Plain {
            let ok = !(err(&pipe) | (q_was_zero & !ge));
            result = Some(pipe.stage("result", "the quotient and its result flag", Quotient { t: q_next, ok }));
            break;
        }
        // Named, so timing reports name the stage (`rem7`, `quot7`).
        part = if form == StageForm::Plain {
            let p = ge.select(diff, p3.resize(wd)).name(&format!("rem{k}"));
            let next = pipe.stage(&format!("q{k}"), "one quotient bit", Partial { p, q: q_next });
            Candidates { p: next.p, q: next.q, ..part }
        } else {
            let (diff, p) = (diff.name(&format!("rem{k}")), p3.resize(wd).name(&format!("kept{k}")));
            pipe.stage(&format!("q{k}"), "one quotient bit", Candidates { ge, diff, p, q: q_next })
        };
        if k + 1 == qbits {
            // The last quotient bit is registered beside its chain and the flag made in a
            // clock of its own: the flag's register sits by the outputs, far from the chain
            // (a 2.4 ns route measured at 250 MHz).
            let ok = !(err(&pipe) | part.q.eq(0));
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
        for (bits_per_stage, form) in [(1, Plain), (2, Plain), (1, Lookahead), (2, Lookahead)] {
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
