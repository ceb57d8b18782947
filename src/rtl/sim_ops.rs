//! The cycle simulator's operations, decoded once from the netlist's definitions: each binary
//! and unary operator becomes a variant with its masks and sign-extension shifts precomputed,
//! so a cycle does no type arithmetic. Every variant computes exactly what `width::eval_bin`
//! and `width::eval_un` compute for that operator and those types (the simulators agree:
//! `tests/rtl_agree.rs` runs random netlists through this and the batched simulator).

use super::width::{BinOp, Ty, UnOp};

/// The shift that sign-extends a `ty` bit pattern into its i128 value (`Ty::value`): 0 for
/// unsigned and 128-bit types.
fn sext_shift(ty: Ty) -> u32 {
    if ty.signed && ty.width < 128 { 128 - ty.width } else { 0 }
}

/// `Ty::value` with the shift of `sext_shift`.
#[inline(always)]
fn val(bits: u128, shift: u32) -> i128 {
    ((bits << shift) as i128) >> shift
}

#[derive(Clone, Debug)]
pub(super) enum Op {
    And {
        dst: usize,
        a: usize,
        b: usize,
    },
    Or {
        dst: usize,
        a: usize,
        b: usize,
    },
    Xor {
        dst: usize,
        a: usize,
        b: usize,
    },
    Eq {
        dst: usize,
        a: usize,
        b: usize,
    },
    Ne {
        dst: usize,
        a: usize,
        b: usize,
    },
    /// Unsigned comparisons on the bit patterns.
    LtBits {
        dst: usize,
        a: usize,
        b: usize,
    },
    LeBits {
        dst: usize,
        a: usize,
        b: usize,
    },
    /// Comparisons of the values (a signed left operand).
    Lt {
        dst: usize,
        a: usize,
        b: usize,
        sa: u32,
        sb: u32,
    },
    Le {
        dst: usize,
        a: usize,
        b: usize,
        sa: u32,
        sb: u32,
    },
    Add {
        dst: usize,
        a: usize,
        b: usize,
        sa: u32,
        sb: u32,
        mask: u128,
    },
    Sub {
        dst: usize,
        a: usize,
        b: usize,
        sa: u32,
        sb: u32,
        mask: u128,
    },
    Mul {
        dst: usize,
        a: usize,
        b: usize,
        sa: u32,
        sb: u32,
        mask: u128,
    },
    /// `!a` within `mask` (the operand's).
    Not {
        dst: usize,
        a: usize,
        mask: u128,
    },
    Neg {
        dst: usize,
        a: usize,
        sa: u32,
        mask: u128,
    },
    Shl {
        dst: usize,
        a: usize,
        k: u32,
        mask: u128,
    },
    ShrBits {
        dst: usize,
        a: usize,
        k: u32,
    },
    Shr {
        dst: usize,
        a: usize,
        sa: u32,
        k: u32,
        mask: u128,
    },
    Slice {
        dst: usize,
        a: usize,
        lsb: u32,
        mask: u128,
    },
    /// A value re-wrapped in the result's width (`Resize`).
    Resize {
        dst: usize,
        a: usize,
        sa: u32,
        mask: u128,
    },
    Copy {
        dst: usize,
        a: usize,
    },
    Mux {
        dst: usize,
        sel: usize,
        t: usize,
        f: usize,
    },
    Case {
        dst: usize,
        sel: usize,
        arms: Vec<(u128, usize)>,
        default: usize,
    },
    Concat {
        dst: usize,
        parts: Vec<(usize, u32)>,
    },
}

impl Op {
    /// `dst = a op b` with the types of the operands and the result.
    pub(super) fn bin(op: BinOp, dst: usize, (a, ta): (usize, Ty), (b, tb): (usize, Ty), tr: Ty) -> Op {
        let (sa, sb, mask) = (sext_shift(ta), sext_shift(tb), tr.mask());
        match op {
            BinOp::Add => Op::Add { dst, a, b, sa, sb, mask },
            BinOp::Sub => Op::Sub { dst, a, b, sa, sb, mask },
            BinOp::Mul => Op::Mul { dst, a, b, sa, sb, mask },
            BinOp::And => Op::And { dst, a, b },
            BinOp::Or => Op::Or { dst, a, b },
            BinOp::Xor => Op::Xor { dst, a, b },
            BinOp::Eq => Op::Eq { dst, a, b },
            BinOp::Ne => Op::Ne { dst, a, b },
            BinOp::Lt if !ta.signed => Op::LtBits { dst, a, b },
            BinOp::Le if !ta.signed => Op::LeBits { dst, a, b },
            BinOp::Lt => Op::Lt { dst, a, b, sa, sb },
            BinOp::Le => Op::Le { dst, a, b, sa, sb },
        }
    }

    /// `dst = op a` with the types of the operand and the result.
    pub(super) fn un(op: UnOp, dst: usize, (a, ta): (usize, Ty), tr: Ty) -> Op {
        let (sa, mask) = (sext_shift(ta), tr.mask());
        match op {
            UnOp::Not => Op::Not { dst, a, mask: ta.mask() },
            UnOp::Neg => Op::Neg { dst, a, sa, mask },
            UnOp::Shl(k) => Op::Shl { dst, a, k, mask: ta.mask() },
            UnOp::Shr(k) if !ta.signed => Op::ShrBits { dst, a, k },
            UnOp::Shr(k) => Op::Shr { dst, a, sa, k, mask },
            UnOp::Slice { lsb, width } => Op::Slice { dst, a, lsb, mask: Ty::u(width).mask() },
            UnOp::Resize(_) => Op::Resize { dst, a, sa, mask },
            UnOp::AsSigned | UnOp::AsUnsigned => Op::Copy { dst, a },
        }
    }
}

/// Evaluates `ops` in order over the slots `v`.
pub(super) fn run(ops: &[Op], v: &mut [u128]) {
    for op in ops {
        match *op {
            Op::And { dst, a, b } => v[dst] = v[a] & v[b],
            Op::Or { dst, a, b } => v[dst] = v[a] | v[b],
            Op::Xor { dst, a, b } => v[dst] = v[a] ^ v[b],
            Op::Eq { dst, a, b } => v[dst] = (v[a] == v[b]) as u128,
            Op::Ne { dst, a, b } => v[dst] = (v[a] != v[b]) as u128,
            Op::LtBits { dst, a, b } => v[dst] = (v[a] < v[b]) as u128,
            Op::LeBits { dst, a, b } => v[dst] = (v[a] <= v[b]) as u128,
            Op::Lt { dst, a, b, sa, sb } => v[dst] = (val(v[a], sa) < val(v[b], sb)) as u128,
            Op::Le { dst, a, b, sa, sb } => v[dst] = (val(v[a], sa) <= val(v[b], sb)) as u128,
            Op::Add { dst, a, b, sa, sb, mask } => v[dst] = (val(v[a], sa).wrapping_add(val(v[b], sb)) as u128) & mask,
            Op::Sub { dst, a, b, sa, sb, mask } => v[dst] = (val(v[a], sa).wrapping_sub(val(v[b], sb)) as u128) & mask,
            Op::Mul { dst, a, b, sa, sb, mask } => v[dst] = (val(v[a], sa).wrapping_mul(val(v[b], sb)) as u128) & mask,
            Op::Not { dst, a, mask } => v[dst] = !v[a] & mask,
            Op::Neg { dst, a, sa, mask } => v[dst] = (val(v[a], sa).wrapping_neg() as u128) & mask,
            Op::Shl { dst, a, k, mask } => v[dst] = (v[a] << k) & mask,
            Op::ShrBits { dst, a, k } => v[dst] = v[a] >> k,
            Op::Shr { dst, a, sa, k, mask } => v[dst] = ((val(v[a], sa) >> k) as u128) & mask,
            Op::Slice { dst, a, lsb, mask } => v[dst] = (v[a] >> lsb) & mask,
            Op::Resize { dst, a, sa, mask } => v[dst] = (val(v[a], sa) as u128) & mask,
            Op::Copy { dst, a } => v[dst] = v[a],
            Op::Mux { dst, sel, t, f } => v[dst] = if v[sel] & 1 == 1 { v[t] } else { v[f] },
            Op::Case { dst, sel, ref arms, default } => {
                let s = v[sel];
                v[dst] = v[arms.iter().find(|arm| arm.0 == s).map_or(default, |arm| arm.1)];
            }
            Op::Concat { dst, ref parts } => {
                v[dst] = parts.iter().fold(0u128, |acc, &(p, w)| if w >= 128 { v[p] } else { (acc << w) | v[p] })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtl::width::{eval_bin, eval_un};

    /// Every decoded operator gives `eval_bin`'s and `eval_un`'s bits, over widths 1–128 of both
    /// signednesses and operands at and around the edges of their ranges.
    #[test]
    fn decoded_operators_compute_what_the_width_rules_say() {
        let mut rng = crate::rng::SplitMix64(29);
        let widths = [1u32, 2, 3, 7, 8, 16, 31, 32, 33, 63, 64, 65, 100, 127, 128];
        let mut ty = || {
            let w = widths[(rng.next_u64() % widths.len() as u64) as usize];
            let signed = rng.next_u64() & 1 == 1;
            let bits = ((rng.next_u64() as u128) << 64) | rng.next_u64() as u128;
            let edge = [0u128, 1, u128::MAX, 1u128 << (w - 1), (1u128 << (w - 1)).wrapping_sub(1)];
            let pick = rng.next_u64() % 8;
            let t = Ty { width: w, signed };
            (t, t.mask() & if pick < 5 { edge[pick as usize] } else { bits })
        };
        let bins = [
            BinOp::Add,
            BinOp::Sub,
            BinOp::And,
            BinOp::Or,
            BinOp::Xor,
            BinOp::Mul,
            BinOp::Eq,
            BinOp::Ne,
            BinOp::Lt,
            BinOp::Le,
        ];
        for i in 0..20_000 {
            let ((ta, a), (tb, b), (tr, _)) = (ty(), ty(), ty());
            let op = bins[i % bins.len()];
            // The builder multiplies only where wa + wb ≤ 128.
            if op == BinOp::Mul && ta.width + tb.width > 128 {
                continue;
            }
            let mut v = vec![a, b, 0];
            run(&[Op::bin(op, 2, (0, ta), (1, tb), tr)], &mut v);
            assert_eq!(v[2], eval_bin(op, ta, a, tb, b, tr), "{op:?} {ta:?} {a:#x} {tb:?} {b:#x} -> {tr:?}");
            let k = (b % ta.width as u128) as u32;
            for un in [
                UnOp::Not,
                UnOp::Neg,
                UnOp::Shl(k),
                UnOp::Shr(k),
                UnOp::Slice { lsb: k, width: (ta.width - k).max(1) },
                UnOp::Resize(tr.width),
                UnOp::AsSigned,
                UnOp::AsUnsigned,
            ] {
                let mut v = vec![a, 0];
                run(&[Op::un(un, 1, (0, ta), tr)], &mut v);
                assert_eq!(v[1], eval_un(un, ta, a, tr), "{un:?} {ta:?} {a:#x} -> {tr:?}");
            }
        }
    }
}
