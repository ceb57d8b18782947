//! Multipliers built for a clock target. A wide product made in one clock is the slowest
//! thing an FPGA does: yosys leaves inferred ECP5 multipliers without their internal
//! registers, and a 32×32 product registered only at its ports reaches 84 MHz on an
//! LFE5U-85F at speed 6 (`../shared/docs/ANCHORS.md`). So a product is cut into DSP-sized
//! pieces here, each piece gets the registers a DSP block has inside (input, pipeline,
//! output), and the pieces are summed in an adder tree with a register after every few
//! levels — all chosen by `MulStyle`, the same values at every style, only the latency moves.
//!
//! Pieces: an operand is cut into unsigned 17-bit limbs from the bottom and a top limb that
//! keeps its sign; every limb is then an 18-bit signed number, so every piece product is one
//! signed 18×18 multiply — one MULT18X18D on ECP5, one DSP48E on Virtex-5 (which would take
//! 25×18; the ECP5 size is used everywhere so one description fits both, DECISIONS.md).

use crate::rtl::build::{Builder, S};
use crate::rtl::{Module, Ty};
use serde::Serialize;
use std::rc::Rc;

/// Unsigned bits of a low limb; limbs are signed LIMB + 1 bits.
pub const LIMB: u32 = 17;

/// How a product is pipelined.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct MulStyle {
    /// Registers around each 18×18 piece: 0 none; 1 the inputs; 2 inputs and output; 3 inputs,
    /// output and one more after it (where a DSP block has its pipeline register); 4 also a
    /// fabric register after the block, where the adder tree picks the piece up (the route
    /// from the DSP column to the tree is then a clock of its own).
    pub dsp_regs: u32,
    /// Adder-tree levels between two registers when the pieces are summed (the last level is
    /// always followed by one); 0 leaves the whole sum combinational.
    pub levels_per_stage: u32,
}

impl MulStyle {
    /// One multiplier, no registers: the product as `xmul` makes it.
    pub const COMBINATIONAL: MulStyle = MulStyle { dsp_regs: 0, levels_per_stage: 0 };

    fn split(self) -> bool {
        self != MulStyle::COMBINATIONAL
    }
}

/// Number of 18-bit limbs an operand of type `t` is cut into.
pub fn limbs(t: Ty) -> u32 {
    let top = if t.signed { LIMB + 1 } else { LIMB };
    if t.width <= top { 1 } else { 1 + (t.width - top).div_ceil(LIMB) }
}

/// Levels of a pairwise adder tree over `terms` terms.
fn tree_levels(terms: u32) -> u32 {
    (terms.max(1) as f64).log2().ceil() as u32
}

/// Clock cycles from a and b to their product for operands `a`, `b` and `style`.
pub fn latency(a: Ty, b: Ty, style: MulStyle) -> u32 {
    if !style.split() {
        return 0;
    }
    let levels = tree_levels(limbs(a) * limbs(b));
    let tree = if style.levels_per_stage == 0 { 0 } else { levels.div_ceil(style.levels_per_stage) };
    style.dsp_regs + tree
}

/// One 18×18 signed piece with `regs` registers (see `MulStyle::dsp_regs`): ports a, b
/// (signed 18 bits) → p (signed 36 bits), `regs` cycles later.
pub fn dsp18_core(regs: u32) -> Module {
    assert!(regs <= 4, "a DSP piece has at most 4 register levels");
    let b = Builder::new(&format!("fxrt_dsp18_r{regs}"));
    let (x, y) = (b.input("a", Ty::s(LIMB + 1)), b.input("b", Ty::s(LIMB + 1)));
    let (x, y) = if regs >= 1 { (b.delay("a_r", x), b.delay("b_r", y)) } else { (x, y) };
    let mut p = x.xmul(y).name("prod");
    for (k, name) in ["p_r", "p_rr", "p_land"].iter().enumerate() {
        if regs >= k as u32 + 2 {
            p = b.delay(name, p);
        }
    }
    b.output("p", p);
    b.finish()
}

/// One product as a module: ports a, b → p (the full product, `xmul`'s type), `latency`
/// cycles later. Named by operand types and style, so equal products share one module.
pub fn product_core(a: Ty, bt: Ty, style: MulStyle) -> Module {
    assert_eq!(a.signed, bt.signed, "a product's operands have one signedness");
    // Partial sums need one bit more than the product.
    assert!(a.width + bt.width < crate::rtl::width::MAX_WIDTH, "a split product needs < 128 bits");
    let b = Builder::new(&format!("fxrt_mul_{}_d{}l{}", kind(a, bt), style.dsp_regs, style.levels_per_stage));
    let (x, y) = (b.input("a", a), b.input("b", bt));
    let p = if style.split() { split_product(&b, x, y, style) } else { x.xmul(y) };
    b.output("p", p);
    b.finish()
}

/// `s30xs48`: the operand types of a product, for module names.
fn kind(a: Ty, b: Ty) -> String {
    let sgn = |t: Ty| if t.signed { "s" } else { "u" };
    format!("{}{}x{}{}", sgn(a), a.width, sgn(b), b.width)
}

/// Multipliers side by side as one module: ports a0, b0, a1, b1, … → p0, p1, …, all
/// `group_latency` cycles later — a `product_core` instance each (one module per distinct
/// product), a product with fewer stages delayed to match, so a pipeline stage can take them
/// together.
pub fn mul_core(ops: &[(Ty, Ty)], style: MulStyle) -> Module {
    let kinds: Vec<String> = ops.iter().map(|&(a, b)| kind(a, b)).collect();
    let b = Builder::new(&format!("fxrt_muls_{}_d{}l{}", kinds.join("_"), style.dsp_regs, style.levels_per_stage));
    let lat = group_latency(ops, style);
    let mut cores: Vec<((Ty, Ty), Rc<Module>)> = Vec::new();
    for (k, &(ta, tb)) in ops.iter().enumerate() {
        let (x, y) = (b.input(&format!("a{k}"), ta), b.input(&format!("b{k}"), tb));
        let core = match cores.iter().find(|c| c.0 == (ta, tb)) {
            Some(c) => c.1.clone(),
            None => {
                let c = Rc::new(product_core(ta, tb, style));
                cores.push(((ta, tb), c.clone()));
                c
            }
        };
        let p = b.instance(&format!("u_m{k}"), &core, &[x, y]).get("p");
        let own = latency(ta, tb, style);
        let p = if lat > own { b.delay_line(&format!("p{k}_pad"), p, lat - own) } else { p };
        b.output(&format!("p{k}"), p);
    }
    b.finish()
}

/// The latency of `mul_core(ops, style)`: its slowest product's.
pub fn group_latency(ops: &[(Ty, Ty)], style: MulStyle) -> u32 {
    ops.iter().map(|&(a, b)| latency(a, b, style)).max().unwrap_or(0)
}

/// A term of the adder tree: `s · 2^off`.
#[derive(Clone, Copy)]
struct Term<'b> {
    s: S<'b>,
    off: u32,
}

/// The limbs of `x`, lowest first, each signed LIMB + 1 bits.
fn limbs_of<'b>(x: S<'b>) -> Vec<S<'b>> {
    let t = x.ty();
    let k = limbs(t);
    (0..k)
        .map(|i| {
            let lsb = i * LIMB;
            let w = if i + 1 == k { t.width - lsb } else { LIMB };
            let bits = x.slice(lsb, w);
            let limb = if i + 1 == k && t.signed { bits.signed() } else { bits.xsigned() };
            limb.resize(LIMB + 1).name(&format!("{}_l{i}", x.b.name_of(x.sig)))
        })
        .collect()
}

/// `x` as a signed `w`-bit value: sign-extended, or its low bits when it is wider (the
/// caller knows the value fits).
fn fit<'b>(x: S<'b>, w: u32) -> S<'b> {
    if x.width() > w { x.slice(0, w).signed() } else { x.resize(w) }
}

/// a + b of two terms whose offsets differ by d ≥ 0 (a the lower): the d low bits of `a`
/// pass through, only the rest is added — the adders stay as wide as the pieces. `total`
/// bounds every partial sum: |sum| < 2^(total − 1) (a subset of the pieces of a product
/// of wa + wb bits stays below 2^(wa + wb) in magnitude).
fn add_terms<'b>(lo: Term<'b>, hi: Term<'b>, total: u32, name: &str) -> Term<'b> {
    let d = hi.off - lo.off;
    assert!(d < lo.s.width(), "adder-tree terms always overlap (offsets differ by 17, pieces are 36 bits)");
    let w = ((lo.s.width() - d).max(hi.s.width()) + 1).min(total - hi.off);
    let upper = fit(lo.s >> d, w) + fit(hi.s, w);
    let s = if d == 0 { upper } else { lo.s.b.cat(&[upper, lo.s.slice(0, d)]).signed() };
    Term { s: s.name(name), off: lo.off }
}

fn split_product<'b>(b: &'b Builder, x: S<'b>, y: S<'b>, style: MulStyle) -> S<'b> {
    let width = x.width() + y.width();
    let dsp = Rc::new(dsp18_core(style.dsp_regs));
    let (xl, yl) = (limbs_of(x), limbs_of(y));
    // Pieces ordered by offset, so neighbours in the tree overlap and sums stay narrow.
    let mut pieces: Vec<(u32, usize, usize)> =
        (0..xl.len()).flat_map(|i| (0..yl.len()).map(move |j| ((i + j) as u32, i, j))).collect();
    pieces.sort();
    let mut terms: Vec<Term> = pieces
        .iter()
        .map(|&(k, i, j)| {
            let p = b.instance(&format!("u_piece{i}{j}"), &dsp, &[xl[i], yl[j]]).get("p");
            Term { s: p.name(&format!("piece{i}{j}")), off: k * LIMB }
        })
        .collect();
    let mut level = 0;
    while terms.len() > 1 {
        let next: Vec<Term> = terms
            .chunks(2)
            .enumerate()
            .map(
                |(i, c)| if c.len() == 2 { add_terms(c[0], c[1], width + 1, &format!("sum{level}_{i}")) } else { c[0] },
            )
            .collect();
        level += 1;
        let last = next.len() == 1;
        let register = style.levels_per_stage > 0 && (level % style.levels_per_stage == 0 || last);
        terms = if register {
            next.iter()
                .enumerate()
                .map(|(i, t)| Term { s: b.delay(&format!("sum{level}_{i}_r"), t.s), off: t.off })
                .collect()
        } else {
            next
        };
    }
    let total = terms[0];
    assert_eq!(total.off, 0, "the lowest piece sits at bit 0");
    // The sum is the exact product, which fits `width` bits of the product's type.
    let bits = fit(total.s, width + 1).slice(0, width);
    if x.ty().signed { bits.signed() } else { bits }
}

/// The products `a · b` of `ops` inside a pipeline, side by side: one `mul_core` instance
/// whose latency the pipeline counts (none when the style is combinational).
pub fn pipe_muls<'b>(
    pipe: &crate::rtl::pipeline::Pipeline<'b>,
    label: &str,
    ops: &[(S<'b>, S<'b>)],
    style: MulStyle,
) -> Vec<S<'b>> {
    if !style.split() {
        return ops.iter().map(|&(a, b)| pipe.now(a).xmul(pipe.now(b))).collect();
    }
    let tys: Vec<(Ty, Ty)> = ops.iter().map(|(a, b)| (a.ty(), b.ty())).collect();
    let inputs: Vec<S<'b>> = ops.iter().flat_map(|&(a, b)| [a, b]).collect();
    let m = Rc::new(mul_core(&tys, style));
    let ports = pipe.instance(label, &m, &inputs, group_latency(&tys, style));
    (0..ops.len()).map(|k| ports.get(&format!("p{k}"))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtl::sim::Sim;
    use proptest::prelude::*;

    /// Every style gives the exact product at its stated latency, back to back, for signed and
    /// unsigned operands from 1 to 63 bits.
    /// Two products side by side (a·b and a·a, different latencies, padded to one).
    fn check(a: Ty, b: Ty, style: MulStyle, vals: &[(i128, i128)]) {
        let m = mul_core(&[(a, b), (a, a)], style);
        let lat = group_latency(&[(a, b), (a, a)], style) as usize;
        let mut sim = Sim::new(&m);
        let h = |k: usize| m.handle(m.inputs[k]);
        let (p, q) = (m.handle(m.outputs[0].1), m.handle(m.outputs[1].1));
        let mut got = Vec::new();
        for i in 0..vals.len() + lat {
            let (x, y) = vals.get(i).copied().unwrap_or((0, 0));
            for (k, v) in [x, y, x, x].into_iter().enumerate() {
                sim.set(h(k), v);
            }
            if lat == 0 {
                sim.eval();
                got.push((sim.get(p), sim.get(q)));
            }
            sim.tick();
            if lat > 0 && i + 1 >= lat {
                got.push((sim.get(p), sim.get(q)));
            }
        }
        for (k, &(x, y)) in vals.iter().enumerate() {
            assert_eq!(got[k], (x * y, x * x), "{a:?} × {b:?} {style:?}: {x} · {y}");
        }
    }

    const STYLES: [MulStyle; 6] = [
        MulStyle::COMBINATIONAL,
        MulStyle { dsp_regs: 0, levels_per_stage: 1 },
        MulStyle { dsp_regs: 2, levels_per_stage: 0 },
        MulStyle { dsp_regs: 2, levels_per_stage: 2 },
        MulStyle { dsp_regs: 3, levels_per_stage: 1 },
        MulStyle { dsp_regs: 4, levels_per_stage: 1 },
    ];

    proptest! {
        #[test]
        fn products_are_exact_at_every_style(
            wa in 1u32..=63, wb in 1u32..=63, signed in any::<bool>(),
            raw in prop::collection::vec((any::<u64>(), any::<u64>()), 40),
        ) {
            let (a, b) = if signed { (Ty::s(wa.max(2)), Ty::s(wb.max(2))) } else { (Ty::u(wa), Ty::u(wb)) };
            let mask = |t: Ty, v: u64| t.value(v as u128 & t.mask());
            let mut vals: Vec<(i128, i128)> = raw.iter().map(|&(x, y)| (mask(a, x), mask(b, y))).collect();
            // The extremes: most negative and largest values.
            let ((amin, amax), (bmin, bmax)) = (a.range(), b.range());
            vals.extend([(amin, bmin), (amax, bmax), (amin, bmax), (amax, bmin)]);
            for style in STYLES {
                check(a, b, style, &vals);
            }
        }
    }

    #[test]
    fn latency_counts_dsp_registers_and_registered_tree_levels() {
        // 48 × 30 signed: 3 × 2 limbs, 6 pieces, 3 tree levels.
        let (a, b) = (Ty::s(48), Ty::s(30));
        assert_eq!((limbs(a), limbs(b)), (3, 2));
        assert_eq!(latency(a, b, MulStyle::COMBINATIONAL), 0);
        assert_eq!(latency(a, b, MulStyle { dsp_regs: 3, levels_per_stage: 1 }), 6);
        assert_eq!(latency(a, b, MulStyle { dsp_regs: 2, levels_per_stage: 2 }), 4);
        assert_eq!(latency(a, b, MulStyle { dsp_regs: 2, levels_per_stage: 0 }), 2);
        // 18 × 18 signed is one piece: no tree, only the piece's own registers.
        assert_eq!(latency(Ty::s(18), Ty::s(18), MulStyle { dsp_regs: 3, levels_per_stage: 1 }), 3);
    }
}
