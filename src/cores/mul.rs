//! Multipliers built for a clock target. A wide product made in one clock is the slowest
//! thing an FPGA does: yosys leaves inferred ECP5 multipliers without their internal
//! registers, and a 32×32 product registered only at its ports reaches 84 MHz on an
//! LFE5U-85F at speed 6 (`../shared/docs/ANCHORS.md`). So a product is cut into DSP-sized
//! pieces here, each piece gets the registers a DSP block has inside (input, pipeline,
//! output), and the pieces are summed in an adder tree with a register after every few
//! levels — all chosen by `MulStyle`, the same values at every style, only the latency moves.
//!
//! Pieces: an operand is cut into unsigned limbs from the bottom and a top limb that keeps its
//! sign. For ECP5 (`Piece::Mult18`) every limb has 17 bits and is an 18-bit signed number, so
//! every piece product is one signed 18×18 multiply, one MULT18X18D (and one DSP48E on Xilinx).
//! For the Xilinx parts (`Piece::Dsp48`) a product whose pieces are fewer that way cuts one
//! operand into 24-bit limbs: every piece is then one 25×18 DSP48E multiply (the plane
//! distance's 30 × 48 bits: 4 pieces, not 6; DECISIONS 131). Other products keep the 18×18
//! cut, so their modules are the ECP5 ones.

use crate::rtl::build::{Builder, S};
use crate::rtl::{Module, Ty};
use serde::{Deserialize, Serialize};
use std::rc::Rc;

/// Unsigned bits of a low limb of an 18-bit port; limbs are signed LIMB + 1 bits.
pub const LIMB: u32 = 17;
/// Unsigned bits of a low limb of a DSP48E's 25-bit port.
pub const WIDE_LIMB: u32 = 24;

/// The hard multiplier a product's pieces are cut for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Piece {
    /// 18 × 18 signed: the ECP5's MULT18X18D (the default build's, placed with nextpnr).
    #[default]
    #[serde(rename = "18x18")]
    Mult18,
    /// 25 × 18 signed: the Xilinx parts' DSP48E (Virtex-5) and DSP48E1 (7 series).
    #[serde(rename = "25x18")]
    Dsp48,
}

impl Piece {
    pub fn is_mult18(&self) -> bool {
        *self == Piece::Mult18
    }
    /// Its operand widths as `--dsp` names them: `18x18` or `25x18`.
    pub fn label(self) -> &'static str {
        match self {
            Piece::Mult18 => "18x18",
            Piece::Dsp48 => "25x18",
        }
    }
    /// What the names of modules built for it end in: nothing for the ECP5's (so its files
    /// are those of every build before), `_dsp48` for the Xilinx parts'.
    pub fn name_suffix(self) -> &'static str {
        match self {
            Piece::Mult18 => "",
            Piece::Dsp48 => "_dsp48",
        }
    }
}

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
    /// The multiplier the pieces are cut for.
    pub piece: Piece,
}

impl MulStyle {
    /// One multiplier, no registers: the product as `xmul` makes it.
    pub const COMBINATIONAL: MulStyle = MulStyle { dsp_regs: 0, levels_per_stage: 0, piece: Piece::Mult18 };

    /// Whether products are cut into pieces (any registers at all).
    pub fn split(self) -> bool {
        self.dsp_regs != 0 || self.levels_per_stage != 0
    }

    /// This style with its pieces cut for `piece`.
    pub fn with_piece(self, piece: Piece) -> MulStyle {
        MulStyle { piece, ..self }
    }

    /// This style with every piece's product landed in a fabric register after the DSP block
    /// (`dsp_regs` at least 4): what a spread core (`clock::spread`) builds, whose DSP columns
    /// lie far from the adder trees that pick the pieces up.
    pub fn landed(self) -> MulStyle {
        MulStyle { dsp_regs: self.dsp_regs.max(4), ..self }
    }

    /// Whether every piece's product lands in a fabric register (`landed`): a spread core's.
    pub fn is_landed(self) -> bool {
        self.dsp_regs >= 4
    }
}

/// Number of limbs of `limb` unsigned bits (the top one signed when `t` is) an operand of type
/// `t` is cut into.
fn limbs_of_width(t: Ty, limb: u32) -> u32 {
    let top = if t.signed { limb + 1 } else { limb };
    if t.width <= top { 1 } else { 1 + (t.width - top).div_ceil(limb) }
}

/// Number of 18-bit limbs an operand of type `t` is cut into.
pub fn limbs(t: Ty) -> u32 {
    limbs_of_width(t, LIMB)
}

/// The low-limb widths (a's, b's) a product a · b is cut into under `piece`: 17 and 17, or for
/// a DSP48E 24 on the operand that gives the fewest pieces, when that is fewer.
pub fn limb_widths(a: Ty, b: Ty, piece: Piece) -> (u32, u32) {
    let square = (LIMB, LIMB);
    let count = |(la, lb): (u32, u32)| limbs_of_width(a, la) * limbs_of_width(b, lb);
    match piece {
        Piece::Mult18 => square,
        Piece::Dsp48 => [(WIDE_LIMB, LIMB), (LIMB, WIDE_LIMB)]
            .into_iter()
            .filter(|&w| count(w) < count(square))
            .min_by_key(|&w| count(w))
            .unwrap_or(square),
    }
}

/// Pieces (hard multipliers) of a product a · b under `piece`.
pub fn pieces(a: Ty, b: Ty, piece: Piece) -> u32 {
    let (la, lb) = limb_widths(a, b, piece);
    limbs_of_width(a, la) * limbs_of_width(b, lb)
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
    let levels = tree_levels(pieces(a, b, style.piece));
    let tree = if style.levels_per_stage == 0 { 0 } else { levels.div_ceil(style.levels_per_stage) };
    style.dsp_regs + tree
}

/// One 18×18 signed piece with `regs` registers (see `MulStyle::dsp_regs`): ports a, b
/// (signed 18 bits) → p (signed 36 bits), `regs` cycles later.
pub fn dsp18_core(regs: u32) -> Module {
    dsp_core(regs, LIMB)
}

/// The name of a DSP48E-sized piece's module, but for its register levels.
pub const DSP48_MODULE_PREFIX: &str = "fxrt_dsp25x18_r";

/// One signed piece of (`a_limb` + 1) × 18 bits with `regs` registers: `fxrt_dsp18_r…` (the
/// 18×18 piece) or `fxrt_dsp25x18_r…` (a DSP48E's 25×18, `a_limb` = `WIDE_LIMB`).
fn dsp_core(regs: u32, a_limb: u32) -> Module {
    assert!(regs <= 4, "a DSP piece has at most 4 register levels");
    let name = if a_limb == LIMB { format!("fxrt_dsp18_r{regs}") } else { format!("{DSP48_MODULE_PREFIX}{regs}") };
    let b = Builder::new(&name);
    let (x, y) = (b.input("a", Ty::s(a_limb + 1)), b.input("b", Ty::s(LIMB + 1)));
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
    let b = Builder::new(&format!("fxrt_mul_{}_d{}l{}", kind(a, bt, style), style.dsp_regs, style.levels_per_stage));
    let (x, y) = (b.input("a", a), b.input("b", bt));
    let p = if style.split() { split_product(&b, x, y, style) } else { x.xmul(y) };
    b.output("p", p);
    b.finish()
}

/// `s30xs48`: the operand types of a product, for module names; `s30xs48_p25` when its
/// pieces are DSP48E's 25 × 18.
fn kind(a: Ty, b: Ty, style: MulStyle) -> String {
    let sgn = |t: Ty| if t.signed { "s" } else { "u" };
    let wide = limb_widths(a, b, style.piece) != (LIMB, LIMB) && style.split();
    format!("{}{}x{}{}{}", sgn(a), a.width, sgn(b), b.width, if wide { "_p25" } else { "" })
}

/// Multipliers side by side as one module: ports a0, b0, a1, b1, … → p0, p1, …, all
/// `group_latency` cycles later — a `product_core` instance each (one module per distinct
/// product), a product with fewer stages delayed to match, so a pipeline stage can take them
/// together.
pub fn mul_core(ops: &[(Ty, Ty)], style: MulStyle) -> Module {
    let kinds: Vec<String> = ops.iter().map(|&(a, b)| kind(a, b, style)).collect();
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

/// The limbs of `x`, lowest first, each signed `limb` + 1 bits.
fn limbs_of<'b>(x: S<'b>, limb: u32) -> Vec<S<'b>> {
    let t = x.ty();
    let k = limbs_of_width(t, limb);
    (0..k)
        .map(|i| {
            let lsb = i * limb;
            let w = if i + 1 == k { t.width - lsb } else { limb };
            let bits = x.slice(lsb, w);
            let limb_s = if i + 1 == k && t.signed { bits.signed() } else { bits.xsigned() };
            limb_s.resize(limb + 1).name(&format!("{}_l{i}", x.b.name_of(x.sig)))
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
    assert!(d < lo.s.width(), "adder-tree terms always overlap (offsets differ by a limb, pieces are wider)");
    let w = ((lo.s.width() - d).max(hi.s.width()) + 1).min(total - hi.off);
    let upper = fit(lo.s >> d, w) + fit(hi.s, w);
    let s = if d == 0 { upper } else { lo.s.b.cat(&[upper, lo.s.slice(0, d)]).signed() };
    Term { s: s.name(name), off: lo.off }
}

fn split_product<'b>(b: &'b Builder, x: S<'b>, y: S<'b>, style: MulStyle) -> S<'b> {
    let width = x.width() + y.width();
    let (lx, ly) = limb_widths(x.ty(), y.ty(), style.piece);
    // The DSP's wide port (a) takes the operand cut into wide limbs.
    let dsp = Rc::new(dsp_core(style.dsp_regs, lx.max(ly)));
    let (xl, yl) = (limbs_of(x, lx), limbs_of(y, ly));
    // Pieces ordered by offset, so neighbours in the tree overlap and sums stay narrow.
    let mut pieces: Vec<(u32, usize, usize)> =
        (0..xl.len()).flat_map(|i| (0..yl.len()).map(move |j| (i as u32 * lx + j as u32 * ly, i, j))).collect();
    pieces.sort();
    let mut terms: Vec<Term> = pieces
        .iter()
        .map(|&(off, i, j)| {
            let ports = if ly > lx { [yl[j], xl[i]] } else { [xl[i], yl[j]] };
            let p = b.instance(&format!("u_piece{i}{j}"), &dsp, &ports).get("p");
            Term { s: p.name(&format!("piece{i}{j}")), off }
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
        MulStyle { dsp_regs: 0, levels_per_stage: 1, piece: Piece::Mult18 },
        MulStyle { dsp_regs: 2, levels_per_stage: 0, piece: Piece::Mult18 },
        MulStyle { dsp_regs: 2, levels_per_stage: 2, piece: Piece::Mult18 },
        MulStyle { dsp_regs: 3, levels_per_stage: 1, piece: Piece::Mult18 },
        MulStyle { dsp_regs: 4, levels_per_stage: 1, piece: Piece::Mult18 },
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
                if style.split() {
                    check(a, b, style.with_piece(Piece::Dsp48), &vals);
                }
            }
        }
    }

    #[test]
    fn latency_counts_dsp_registers_and_registered_tree_levels() {
        // 48 × 30 signed: 3 × 2 limbs, 6 pieces, 3 tree levels.
        let (a, b) = (Ty::s(48), Ty::s(30));
        assert_eq!((limbs(a), limbs(b)), (3, 2));
        assert_eq!(latency(a, b, MulStyle::COMBINATIONAL), 0);
        assert_eq!(latency(a, b, MulStyle { dsp_regs: 3, levels_per_stage: 1, piece: Piece::Mult18 }), 6);
        assert_eq!(latency(a, b, MulStyle { dsp_regs: 2, levels_per_stage: 2, piece: Piece::Mult18 }), 4);
        assert_eq!(latency(a, b, MulStyle { dsp_regs: 2, levels_per_stage: 0, piece: Piece::Mult18 }), 2);
        // 18 × 18 signed is one piece: no tree, only the piece's own registers.
        assert_eq!(
            latency(Ty::s(18), Ty::s(18), MulStyle { dsp_regs: 3, levels_per_stage: 1, piece: Piece::Mult18 }),
            3
        );
    }

    /// The DSP48E's cut: the plane distance's 30 × 48 bits in 4 pieces of 25 × 18 (48 on the
    /// wide port), not 6; a product it saves nothing on (32 × 32: 4 either way) keeps the
    /// 18 × 18 module, name and all, so a Xilinx build differs only where it gains.
    #[test]
    fn dsp48_pieces_cut_only_the_products_they_shrink() {
        let (a, b) = (Ty::s(30), Ty::s(48));
        assert_eq!((pieces(a, b, Piece::Mult18), pieces(a, b, Piece::Dsp48)), (6, 4));
        assert_eq!(limb_widths(a, b, Piece::Dsp48), (LIMB, WIDE_LIMB));
        let style = MulStyle { dsp_regs: 3, levels_per_stage: 1, piece: Piece::Dsp48 };
        // 4 pieces: two tree levels, one fewer than 18 × 18's six.
        assert_eq!(latency(a, b, style), 5);
        let m = product_core(a, b, style);
        assert_eq!(m.name, "fxrt_mul_s30xs48_p25_d3l1");
        let dsps: Vec<&str> = m.instances.iter().map(|i| i.module.name.as_str()).collect();
        assert_eq!(dsps, ["fxrt_dsp25x18_r3"; 4]);
        let square = (Ty::s(32), Ty::s(32));
        assert_eq!(pieces(square.0, square.1, Piece::Dsp48), 4);
        let same = product_core(square.0, square.1, style.with_piece(Piece::Mult18));
        assert_eq!(product_core(square.0, square.1, style), same);
    }
}
