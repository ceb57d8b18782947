//! Width and sign rules, written once. The builder asks these functions for the type of every
//! node; the value of every operator is defined here (`eval_bin`, `eval_un`, `eval_mux`,
//! `case_arm`, `eval_concat`, gathered per netlist node by `Def::eval`), which the cycle
//! simulator and constant folding call and the batched simulator's specialised kernels are
//! checked against (tests/rtl_agree.rs); the printers never compute a width.
//!
//! Values are bit patterns in a u128, masked to their width; a signed value is two's
//! complement. Operators that grow their result have their own names (`Mul` gives wa + wb
//! bits); everything else wraps at the operand width, and growth is an explicit `Resize`.

use serde::Serialize;

/// Maximum signal width.
pub const MAX_WIDTH: u32 = 128;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct Ty {
    pub width: u32,
    pub signed: bool,
}

impl Ty {
    pub const fn u(width: u32) -> Ty {
        Ty { width, signed: false }
    }
    pub const fn s(width: u32) -> Ty {
        Ty { width, signed: true }
    }
    pub const BIT: Ty = Ty::u(1);

    pub fn mask(&self) -> u128 {
        if self.width >= 128 { u128::MAX } else { (1u128 << self.width) - 1 }
    }
    /// The bit pattern of `v` (any integer) in this type.
    pub fn wrap(&self, v: i128) -> u128 {
        (v as u128) & self.mask()
    }
    /// The integer a bit pattern stands for.
    pub fn value(&self, bits: u128) -> i128 {
        if self.signed && self.width < 128 && (bits >> (self.width - 1)) & 1 == 1 {
            (bits | !self.mask()) as i128
        } else {
            bits as i128
        }
    }
    /// Smallest and largest values (as i128; u128 128-bit maximum is not representable and
    /// is never needed by the cores).
    pub fn range(&self) -> (i128, i128) {
        match (self.signed, self.width) {
            (true, w) => (-(1i128 << (w - 1)), (1i128 << (w - 1)) - 1),
            (false, 128) => (0, i128::MAX),
            (false, w) => (0, (1i128 << w) - 1),
        }
    }
    pub fn fits(&self, v: i128) -> bool {
        let (lo, hi) = self.range();
        v >= lo && v <= hi
    }
    /// Whether `v` can be given for a value of this type: in range, or for an unsigned
    /// 128-bit type any i128, read as its bit pattern (the top values are no i128).
    pub fn accepts(&self, v: i128) -> bool {
        self.fits(v) || (!self.signed && self.width == 128)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub enum BinOp {
    Add,
    Sub,
    And,
    Or,
    Xor,
    /// Full product: wa + wb bits.
    Mul,
    Eq,
    Ne,
    Lt,
    Le,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub enum UnOp {
    Not,
    Neg,
    /// Shift left by a constant; bits shifted out are lost.
    Shl(u32),
    /// Shift right by a constant: arithmetic for signed, logical for unsigned.
    Shr(u32),
    /// Bits [lsb, lsb + width) as an unsigned value.
    Slice {
        lsb: u32,
        width: u32,
    },
    /// To `width` bits: sign- or zero-extend by the operand's signedness, or keep the low bits.
    Resize(u32),
    /// Reinterpret the bits with the other signedness.
    AsSigned,
    AsUnsigned,
}

/// Why a node cannot be built; the builder turns it into a panic with the node's name, since a
/// core that builds an ill-typed node is a bug in fxrt, not bad user input.
pub type TypeResult = Result<Ty, String>;

pub fn bin_ty(op: BinOp, a: Ty, b: Ty) -> TypeResult {
    use BinOp::*;
    match op {
        Add | Sub | And | Or | Xor => {
            if a != b {
                return Err(format!("{op:?} needs equal types, got {a:?} and {b:?}"));
            }
            Ok(a)
        }
        Mul => {
            if a.signed != b.signed {
                return Err(format!("Mul needs equal signedness, got {a:?} and {b:?}"));
            }
            let w = a.width + b.width;
            if w > MAX_WIDTH {
                return Err(format!("Mul result of {w} bits exceeds {MAX_WIDTH}"));
            }
            Ok(Ty { width: w, signed: a.signed })
        }
        Eq | Ne | Lt | Le => {
            if a != b {
                return Err(format!("{op:?} needs equal types, got {a:?} and {b:?}"));
            }
            Ok(Ty::BIT)
        }
    }
}

pub fn un_ty(op: UnOp, a: Ty) -> TypeResult {
    use UnOp::*;
    match op {
        Not | Neg => Ok(a),
        Shl(k) | Shr(k) => {
            if k >= a.width {
                return Err(format!("shift by {k} of a {}-bit value", a.width));
            }
            Ok(a)
        }
        Slice { lsb, width } => {
            if width == 0 || lsb + width > a.width {
                return Err(format!("slice [{lsb} +: {width}] of a {}-bit value", a.width));
            }
            Ok(Ty::u(width))
        }
        Resize(w) => {
            if w == 0 || w > MAX_WIDTH {
                return Err(format!("resize to {w} bits"));
            }
            Ok(Ty { width: w, signed: a.signed })
        }
        AsSigned => Ok(Ty::s(a.width)),
        AsUnsigned => Ok(Ty::u(a.width)),
    }
}

/// The result bits of a binary operator on operand bits of types `ta`, `tb`.
pub fn eval_bin(op: BinOp, ta: Ty, a: u128, tb: Ty, b: u128, tr: Ty) -> u128 {
    use BinOp::*;
    let (va, vb) = (ta.value(a), tb.value(b));
    match op {
        Add => tr.wrap(va.wrapping_add(vb)),
        Sub => tr.wrap(va.wrapping_sub(vb)),
        And => a & b,
        Or => a | b,
        Xor => a ^ b,
        // wa + wb ≤ 128, so the product of the values fits i128 except u64 × u64 at 128 bits,
        // where wrapping is exact modulo 2^128.
        Mul => tr.wrap(va.wrapping_mul(vb)),
        Eq => (a == b) as u128,
        Ne => (a != b) as u128,
        // An unsigned 128-bit value with its top bit set is no i128: compare the bit patterns.
        Lt if !ta.signed => (a < b) as u128,
        Le if !ta.signed => (a <= b) as u128,
        Lt => (va < vb) as u128,
        Le => (va <= vb) as u128,
    }
}

pub fn eval_un(op: UnOp, ta: Ty, a: u128, tr: Ty) -> u128 {
    use UnOp::*;
    match op {
        Not => !a & ta.mask(),
        Neg => tr.wrap(ta.value(a).wrapping_neg()),
        Shl(k) => (a << k) & ta.mask(),
        // Logical for unsigned (on the bit pattern, so at 128 bits too), arithmetic for signed.
        Shr(k) if !ta.signed => a >> k,
        Shr(k) => tr.wrap(ta.value(a) >> k),
        Slice { lsb, width } => (a >> lsb) & Ty::u(width).mask(),
        Resize(_) => tr.wrap(ta.value(a)),
        AsSigned | AsUnsigned => a,
    }
}

/// A 2-way mux: `t` when bit 0 of `sel` is 1.
#[inline]
pub fn eval_mux(sel: u128, t: u128, f: u128) -> u128 {
    if sel & 1 == 1 { t } else { f }
}

/// The arm a `case` takes: the first whose pattern equals the selector's **bit pattern**
/// (whatever the selector's signedness: a signed 2-bit −1 is pattern 3), else None (the
/// default). VHDL's `with … select` on bit strings and Verilog's `case` on sized literals
/// compare the same way.
#[inline]
pub fn case_arm(sel_bits: u128, mut patterns: impl Iterator<Item = u128>) -> Option<usize> {
    patterns.position(|p| p == sel_bits)
}

/// A concatenation of (width, bits) parts, most significant first; unsigned.
#[inline]
pub fn eval_concat(parts: impl Iterator<Item = (u32, u128)>) -> u128 {
    parts.fold(0u128, |acc, (w, v)| if w >= 128 { v } else { (acc << w) | v })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every operator on every pair of 8-bit (and mixed 5/3-bit) operands against plain
    /// Rust integer arithmetic.
    #[test]
    fn exhaustive_8_bit() {
        for signed in [false, true] {
            let t = Ty { width: 8, signed };
            let int = |bits: u128| -> i64 { if signed { bits as u8 as i8 as i64 } else { bits as u8 as i64 } };
            for a in 0..256u128 {
                for b in 0..256u128 {
                    let (x, y) = (int(a), int(b));
                    let bin = |op| eval_bin(op, t, a, t, b, bin_ty(op, t, t).unwrap());
                    assert_eq!(bin(BinOp::Add), (x + y) as u8 as u128);
                    assert_eq!(bin(BinOp::Sub), (x - y) as u8 as u128);
                    assert_eq!(bin(BinOp::Mul), (x * y) as u16 as u128);
                    assert_eq!(bin(BinOp::Lt), (x < y) as u128);
                    assert_eq!(bin(BinOp::Le), (x <= y) as u128);
                    assert_eq!(bin(BinOp::Eq), (x == y) as u128);
                    assert_eq!(bin(BinOp::Xor), a ^ b);
                }
                let x = int(a);
                let un = |op| eval_un(op, t, a, un_ty(op, t).unwrap());
                for k in 0..8 {
                    assert_eq!(un(UnOp::Shl(k)), ((x << k) as u8) as u128);
                    assert_eq!(un(UnOp::Shr(k)), ((x >> k) as u8) as u128);
                }
                assert_eq!(un(UnOp::Neg), (x.wrapping_neg()) as u8 as u128);
                assert_eq!(un(UnOp::Not), !(a as u8) as u128);
                assert_eq!(un(UnOp::Resize(12)), (x as u16 & 0xFFF) as u128);
                assert_eq!(un(UnOp::Resize(5)), a & 0x1F);
                assert_eq!(un(UnOp::Slice { lsb: 3, width: 4 }), (a >> 3) & 0xF);
            }
        }
    }

    /// Unsigned values with the top bit set compare and shift as unsigned at every width,
    /// 128 included.
    #[test]
    fn unsigned_top_bit() {
        for w in [8u32, 63, 64, 65, 127, 128] {
            let t = Ty::u(w);
            let top = 1u128 << (w - 1);
            assert_eq!(eval_bin(BinOp::Lt, t, 1, t, top, Ty::BIT), 1, "{w}");
            assert_eq!(eval_bin(BinOp::Le, t, top, t, 1, Ty::BIT), 0, "{w}");
            assert_eq!(eval_un(UnOp::Shr(1), t, top, t), top >> 1, "{w}");
            let s = Ty::s(w);
            assert_eq!(eval_bin(BinOp::Lt, s, top, s, 1, Ty::BIT), 1, "{w} signed");
            assert_eq!(eval_un(UnOp::Shr(1), s, top, s), top | (top >> 1), "{w} signed");
        }
    }

    #[test]
    fn wide_values() {
        let t = Ty::s(128);
        assert_eq!(t.value(u128::MAX), -1);
        let p = eval_bin(
            BinOp::Mul,
            Ty::s(64),
            Ty::s(64).wrap(-3),
            Ty::s(64),
            Ty::s(64).wrap(i64::MAX as i128),
            Ty::s(128),
        );
        assert_eq!(Ty::s(128).value(p), -3 * i64::MAX as i128);
        assert!(bin_ty(BinOp::Mul, Ty::s(64), Ty::s(65)).is_err());
        assert!(bin_ty(BinOp::Add, Ty::s(8), Ty::u(8)).is_err());
        assert!(un_ty(UnOp::Slice { lsb: 4, width: 5 }, Ty::u(8)).is_err());
    }
}
