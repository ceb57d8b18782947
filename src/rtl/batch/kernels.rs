//! The evaluation kernels of the batched simulator, on extended integers (a value of type t
//! held as its two's-complement integer): i64 loops for signals up to 64 bits, i128 loops
//! beyond, a per-value form for state machines, and `Def::eval` (the definition, on bit
//! patterns) for everything else. The kernels are checked against `Def::eval` on random
//! netlists (tests/rtl_agree.rs). Unsigned 64- and 128-bit values do not fit their lanes as extended
//! integers and always take the wider or the general path.

use crate::rtl::netlist::Def;
use crate::rtl::width::{BinOp, Ty, UnOp};

/// `x` wrapped to a type of 128 − `sh` bits as an extended integer.
#[inline(always)]
pub fn fit128(x: i128, sh: u32, signed: bool) -> i128 {
    if signed { (x << sh) >> sh } else { ((x as u128) << sh >> sh) as i128 }
}

/// i128 loops for the wide operators the cores use. Unsigned 128-bit values do not fit an
/// i128 as extended integers, so anything involving one is left to the general path.
pub fn wide_kernel(def: &Def, tys: &[Ty], tr: Ty, s: &[Vec<i128>], o: &mut [i128]) -> bool {
    if tys.iter().chain([&tr]).any(|t| t.width == 128 && !t.signed) {
        return false;
    }
    let (sh, sg) = (128 - tr.width, tr.signed);
    match def {
        Def::Bin(op, ..) => {
            let (a, b) = (&s[0], &s[1]);
            let f: fn(i128, i128) -> i128 = match op {
                BinOp::Add => |a, b| a.wrapping_add(b),
                BinOp::Sub => |a, b| a.wrapping_sub(b),
                BinOp::Mul => |a, b| a.wrapping_mul(b),
                BinOp::And => |a, b| a & b,
                BinOp::Or => |a, b| a | b,
                BinOp::Xor => |a, b| a ^ b,
                BinOp::Eq => |a, b| (a == b) as i128,
                BinOp::Ne => |a, b| (a != b) as i128,
                BinOp::Lt => |a, b| (a < b) as i128,
                BinOp::Le => |a, b| (a <= b) as i128,
            };
            for ((o, &x), &y) in o.iter_mut().zip(a).zip(b) {
                *o = fit128(f(x, y), sh, sg);
            }
        }
        Def::Un(op, _) => {
            let a = &s[0];
            match *op {
                UnOp::Shr(k) => o.iter_mut().zip(a).for_each(|(o, &x)| *o = x >> k),
                UnOp::Shl(k) => o.iter_mut().zip(a).for_each(|(o, &x)| *o = fit128(x << k, sh, sg)),
                UnOp::Slice { lsb, .. } => o.iter_mut().zip(a).for_each(|(o, &x)| *o = fit128(x >> lsb, sh, false)),
                UnOp::Resize(_) | UnOp::AsSigned | UnOp::AsUnsigned => {
                    o.iter_mut().zip(a).for_each(|(o, &x)| *o = fit128(x, sh, sg))
                }
                UnOp::Not => o.iter_mut().zip(a).for_each(|(o, &x)| *o = fit128(!x, sh, sg)),
                UnOp::Neg => o.iter_mut().zip(a).for_each(|(o, &x)| *o = fit128(x.wrapping_neg(), sh, sg)),
            }
        }
        Def::Mux { .. } => {
            for (((o, &c), &x), &y) in o.iter_mut().zip(&s[0]).zip(&s[1]).zip(&s[2]) {
                *o = if c != 0 { x } else { y };
            }
        }
        _ => return false,
    }
    true
}

/// `x` wrapped to `t` as an extended integer (t.width ≤ 64).
#[inline(always)]
pub fn fit(x: i64, sh: u32, signed: bool) -> i64 {
    if signed { (x << sh) >> sh } else { ((x as u64) << sh >> sh) as i64 }
}

/// The all-narrow loops. Returns false for what it does not cover (the caller falls back).
pub fn narrow_kernel(def: &Def, tys: &[Ty], tr: Ty, s: &[&[i64]], o: &mut [i64]) -> bool {
    let (sh, sg) = (64 - tr.width, tr.signed);
    macro_rules! lanes {
        (|$a:ident| $e:expr) => {{
            let a = s[0];
            for (o, &$a) in o.iter_mut().zip(a) {
                *o = $e;
            }
        }};
        (|$a:ident, $b:ident| $e:expr) => {{
            let (a, b) = (s[0], s[1]);
            for ((o, &$a), &$b) in o.iter_mut().zip(a).zip(b) {
                *o = $e;
            }
        }};
    }
    match def {
        Def::Bin(op, ..) => match op {
            BinOp::Add => lanes!(|a, b| fit(a.wrapping_add(b), sh, sg)),
            BinOp::Sub => lanes!(|a, b| fit(a.wrapping_sub(b), sh, sg)),
            BinOp::And => lanes!(|a, b| a & b),
            BinOp::Or => lanes!(|a, b| a | b),
            BinOp::Xor => lanes!(|a, b| a ^ b),
            // wa + wb ≤ 64: the product of the values is exact.
            BinOp::Mul => lanes!(|a, b| a.wrapping_mul(b)),
            BinOp::Eq => lanes!(|a, b| (a == b) as i64),
            BinOp::Ne => lanes!(|a, b| (a != b) as i64),
            BinOp::Lt => lanes!(|a, b| (a < b) as i64),
            BinOp::Le => lanes!(|a, b| (a <= b) as i64),
        },
        Def::Un(op, _) => {
            match *op {
                UnOp::Not => lanes!(|a| fit(!a, sh, sg)),
                UnOp::Neg => lanes!(|a| fit(a.wrapping_neg(), sh, sg)),
                UnOp::Shl(k) => lanes!(|a| fit(a << k, sh, sg)),
                // Extended values: >> is arithmetic for signed, logical for unsigned (a ≥ 0).
                UnOp::Shr(k) => lanes!(|a| a >> k),
                UnOp::Slice { lsb, .. } => lanes!(|a| fit(a >> lsb, sh, false)),
                // Reinterpret the operand's bit pattern in the result type.
                UnOp::Resize(_) | UnOp::AsSigned | UnOp::AsUnsigned => lanes!(|a| fit(a, sh, sg)),
            }
        }
        Def::Mux { .. } => {
            let (sel, t, f) = (s[0], s[1], s[2]);
            for (((o, &c), &x), &y) in o.iter_mut().zip(sel).zip(t).zip(f) {
                *o = if c != 0 { x } else { y };
            }
        }
        // Operands: sel, default, arms…; arms match the selector's bit pattern, also when it
        // is signed (a signed 2-bit −1 is pattern 3).
        Def::Case { arms, .. } => {
            let mask = u64::MAX >> (64 - tys[0].width);
            for (c, o) in o.iter_mut().enumerate() {
                let sel = (s[0][c] as u64 & mask) as u128;
                *o = arms.iter().position(|a| a.0 == sel).map_or(s[1][c], |k| s[2 + k][c]);
            }
        }
        // Unsigned parts of at most 64 bits in all: shift and or.
        Def::Concat(_) if !tr.signed => {
            for (c, o) in o.iter_mut().enumerate() {
                let mut acc = 0u64;
                for (t, src) in tys.iter().zip(s) {
                    let part = (src[c] as u64) & (u64::MAX >> (64 - t.width));
                    acc = if t.width >= 64 { part } else { (acc << t.width) | part };
                }
                *o = acc as i64;
            }
        }
        _ => return false,
    }
    true
}

/// One definition on extended values (operands in `comb_inputs` order).
pub fn eval_value(def: &Def, tys: &[Ty], v: &[i128], tr: Ty) -> i128 {
    if tys.iter().chain([&tr]).any(|t| t.width == 128 && !t.signed) {
        let bits: Vec<u128> = tys.iter().zip(v).map(|(t, x)| t.wrap(*x)).collect();
        return tr.value(def.eval(tys, &bits, tr));
    }
    let (sh, sg) = (128 - tr.width, tr.signed);
    match def {
        Def::Bin(op, ..) => {
            let (a, b) = (v[0], v[1]);
            let r = match op {
                BinOp::Add => a.wrapping_add(b),
                BinOp::Sub => a.wrapping_sub(b),
                BinOp::Mul => a.wrapping_mul(b),
                BinOp::And => a & b,
                BinOp::Or => a | b,
                BinOp::Xor => a ^ b,
                BinOp::Eq => (a == b) as i128,
                BinOp::Ne => (a != b) as i128,
                BinOp::Lt => (a < b) as i128,
                BinOp::Le => (a <= b) as i128,
            };
            fit128(r, sh, sg)
        }
        Def::Un(op, _) => {
            let a = v[0];
            match *op {
                UnOp::Shr(k) => a >> k,
                UnOp::Shl(k) => fit128(a << k, sh, sg),
                UnOp::Slice { lsb, .. } => fit128(a >> lsb, sh, false),
                UnOp::Resize(_) | UnOp::AsSigned | UnOp::AsUnsigned => fit128(a, sh, sg),
                UnOp::Not => fit128(!a, sh, sg),
                UnOp::Neg => fit128(a.wrapping_neg(), sh, sg),
            }
        }
        Def::Mux { .. } => {
            if v[0] != 0 {
                v[1]
            } else {
                v[2]
            }
        }
        // comb_inputs order: sel, default, arms…; arms match the selector's bit pattern.
        Def::Case { arms, .. } => {
            let sel = tys[0].wrap(v[0]);
            arms.iter().position(|a| a.0 == sel).map_or(v[1], |k| v[2 + k])
        }
        Def::Concat(_) => {
            let bits = tys
                .iter()
                .zip(v)
                .fold(0u128, |acc, (t, x)| if t.width >= 128 { t.wrap(*x) } else { (acc << t.width) | t.wrap(*x) });
            tr.value(bits)
        }
        other => unreachable!("not combinational: {other:?}"),
    }
}
