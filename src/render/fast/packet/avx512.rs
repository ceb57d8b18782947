//! The packet walk on AVX-512 (F, DQ): a value per lane in two 512-bit registers, a lane mask
//! in the bits of a `u32`; every operation is one instruction per register.

use super::LANES;
use crate::model::golden::{Golden, GridRay, Hit};
use crate::render::fast::{FastScene, LEAF};
use std::arch::x86_64::*;
use std::mem::MaybeUninit;

/// Registers per value: a packet has 8·N lanes.
const N: usize = 2;
const PACKET: usize = 8 * N;
/// A value per lane, and a bit per lane.
type W = [__m512i; N];
type Mask = u32;

fn to_w(a: [i64; PACKET]) -> W {
    // SAFETY: both are 8·N plain i64.
    unsafe { std::mem::transmute(a) }
}

fn to_a(w: W) -> [i64; PACKET] {
    // SAFETY: as above.
    unsafe { std::mem::transmute(w) }
}

// Lane-wise operations: one AVX-512 instruction per register.
macro_rules! lanewise {
    ($($name:ident($($arg:ident),*) = $op:expr;)*) => {$(
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn $name($($arg: W),*) -> W {
            std::array::from_fn(|i| $op($($arg[i]),*))
        }
    )*};
}
lanewise! {
    add(a, b) = _mm512_add_epi64;
    sub(a, b) = _mm512_sub_epi64;
    min(a, b) = _mm512_min_epi64;
    max(a, b) = _mm512_max_epi64;
    bit_and(a, b) = _mm512_and_si512;
    bit_or(a, b) = _mm512_or_si512;
    xor(a, b) = _mm512_xor_si512;
    abs_by(a, b) = |a, _| _mm512_abs_epi64(a);
    mul32(a, b) = _mm512_mul_epi32;
    // A lane with b = 0 converts ±inf or NaN to i64::MIN (negative).
    div_f64(a, b) = |a, b| _mm512_cvttpd_epi64(_mm512_div_pd(_mm512_cvtepi64_pd(a), _mm512_cvtepi64_pd(b)));
    mul_lo32(a, b) = |a, b| _mm512_add_epi64(_mm512_mul_epu32(a, b), _mm512_slli_epi64::<32>(_mm512_mul_epu32(a, _mm512_srli_epi64::<32>(b))));
    sign(a) = _mm512_srai_epi64::<63>;
    div64(a) = _mm512_srai_epi64::<6>;
}

macro_rules! compare {
    ($($name:ident = $op:ident;)*) => {$(
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn $name(a: W, b: W) -> Mask {
            (0..N).fold(0, |m, i| m | ($op(a[i], b[i]) as Mask) << (8 * i))
        }
    )*};
}
compare! { le = _mm512_cmple_epi64_mask; lt = _mm512_cmplt_epi64_mask; ge = _mm512_cmpge_epi64_mask; le_unsigned = _mm512_cmple_epu64_mask; }

#[inline]
#[target_feature(enable = "avx512f,avx512dq")]
fn negative(a: W) -> Mask {
    (0..N).fold(0, |m, i| m | (_mm512_movepi64_mask(a[i]) as Mask) << (8 * i))
}

#[inline]
#[target_feature(enable = "avx512f,avx512dq")]
fn splat(x: i64) -> W {
    [_mm512_set1_epi64(x); N]
}

/// For a factor of `mul32` (which reads the low 32 bits of a lane): one broadcast.
#[inline]
#[target_feature(enable = "avx512f,avx512dq")]
fn splat32(x: i64) -> W {
    [_mm512_set1_epi32(x as i32); N]
}

/// `b` in the lanes of `m`, `a` elsewhere.
#[inline]
#[target_feature(enable = "avx512f,avx512dq")]
fn blend(m: Mask, a: W, b: W) -> W {
    std::array::from_fn(|i| _mm512_mask_blend_epi64((m >> (8 * i)) as u8, a[i], b[i]))
}

/// Arithmetic right (`sra`) or logical left (`sll`) shift of every lane by `s`.
#[inline]
#[target_feature(enable = "avx512f,avx512dq")]
fn sra(a: W, s: u32) -> W {
    a.map(|x| _mm512_sra_epi64(x, _mm_set_epi64x(0, s as i64)))
}

#[inline]
#[target_feature(enable = "avx512f,avx512dq")]
fn sra_small(a: W, s: u32) -> W {
    sra(a, s)
}

#[inline]
#[target_feature(enable = "avx512f,avx512dq")]
fn sll(a: W, s: u32) -> W {
    a.map(|x| _mm512_sll_epi64(x, _mm_set_epi64x(0, s as i64)))
}

// The lane masks.
fn both(a: Mask, b: Mask) -> Mask {
    a & b
}

fn either(a: Mask, b: Mask) -> Mask {
    a | b
}

fn any(a: Mask) -> bool {
    a != 0
}

fn count(a: Mask) -> u32 {
    a.count_ones()
}

/// Every lane if `b`, else none.
fn all_if(b: bool) -> Mask {
    if b { Mask::MAX } else { 0 }
}

/// The first `len` lanes.
fn first(len: usize) -> Mask {
    ((1u64 << len) - 1) as Mask
}

packet_walk!("avx512f,avx512dq");
