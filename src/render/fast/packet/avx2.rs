//! The packet walk on AVX2: a value per lane in four 256-bit registers, a lane mask in the
//! sign bits of four registers (what `cmpgt`, `blendv`, `movemask` and `testz` read and write).
//! AVX2 has no 64-bit min, max, abs, arithmetic shift or i64 ↔ f64 conversion; each is built
//! here from a few instructions it has, exactly for the operands the walk gives them.

use super::LANES;
use crate::model::golden::{Golden, GridRay, Hit};
use crate::render::fast::{FastScene, LEAF};
use std::arch::x86_64::*;
use std::mem::MaybeUninit;

/// Registers per value: a packet has 4·N lanes.
const N: usize = 2;
const PACKET: usize = 4 * N;
/// A value per lane; a lane mask is one too (its sign bits).
type W = [__m256i; N];
type Mask = W;

fn to_w(a: [i64; PACKET]) -> W {
    // SAFETY: both are 4·N plain i64.
    unsafe { std::mem::transmute(a) }
}

fn to_a(w: W) -> [i64; PACKET] {
    // SAFETY: as above.
    unsafe { std::mem::transmute(w) }
}

/// One register: `b` where `m`'s sign bit is set, `a` elsewhere.
#[inline]
#[target_feature(enable = "avx2")]
fn select(m: __m256i, a: __m256i, b: __m256i) -> __m256i {
    _mm256_castpd_si256(_mm256_blendv_pd(_mm256_castsi256_pd(a), _mm256_castsi256_pd(b), _mm256_castsi256_pd(m)))
}

/// One register: −1 in the negative lanes, 0 elsewhere.
#[inline]
#[target_feature(enable = "avx2")]
fn negative1(a: __m256i) -> __m256i {
    _mm256_cmpgt_epi64(_mm256_setzero_si256(), a)
}

/// One register, floor(a / 2^s): a logical shift of a with its sign bits flipped to 0, flipped back.
#[inline]
#[target_feature(enable = "avx2")]
fn sra1(a: __m256i, s: __m128i) -> __m256i {
    let m = negative1(a);
    _mm256_xor_si256(_mm256_srl_epi64(_mm256_xor_si256(a, m), s), m)
}

/// One register, 0 ≤ a < 2^63 to the nearest f64: (2^84 + hi·2^32) − (2^84 + 2^52) is exact,
/// and adding 2^52 + lo rounds once (the usual two-halves conversion).
#[inline]
#[target_feature(enable = "avx2")]
fn to_f64(a: __m256i) -> __m256d {
    let (p84, p52) = (_mm256_set1_pd(2f64.powi(84)), _mm256_set1_pd(2f64.powi(52)));
    let hi = _mm256_or_si256(_mm256_srli_epi64::<32>(a), _mm256_castpd_si256(p84));
    let lo = _mm256_blend_epi32::<0b1010_1010>(a, _mm256_castpd_si256(p52));
    _mm256_add_pd(_mm256_sub_pd(_mm256_castsi256_pd(hi), _mm256_add_pd(p84, p52)), _mm256_castsi256_pd(lo))
}

/// One register, floor(a / b) off by at most one for 0 ≤ a, b < 2^63 (as `div_floor`): the
/// quotient y is within 1/4 of a/b, and q = y rounded to the nearest integer (read from the
/// bits of y + 2^52) is floor(a/b) or one more, which the remainder corrects. Where y ≥ 2^52,
/// +inf or NaN (b = 0) the bits give a q ≥ 2^32 or a negative one, outside every window.
#[inline]
#[target_feature(enable = "avx2")]
fn div1(a: __m256i, b: __m256i) -> __m256i {
    let p52 = _mm256_set1_pd(2f64.powi(52));
    let q = _mm256_add_pd(_mm256_div_pd(to_f64(a), to_f64(b)), p52);
    _mm256_sub_epi64(_mm256_castpd_si256(q), _mm256_castpd_si256(p52))
}

// Lane-wise operations, register by register.
macro_rules! lanewise {
    ($($name:ident($($arg:ident),*) = $op:expr;)*) => {$(
        #[inline]
        #[target_feature(enable = "avx2")]
        fn $name($($arg: W),*) -> W {
            std::array::from_fn(|i| $op($($arg[i]),*))
        }
    )*};
}
lanewise! {
    add(a, b) = _mm256_add_epi64;
    sub(a, b) = _mm256_sub_epi64;
    min(a, b) = |a, b| select(_mm256_cmpgt_epi64(a, b), a, b);
    max(a, b) = |a, b| select(_mm256_cmpgt_epi64(a, b), b, a);
    bit_and(a, b) = _mm256_and_si256;
    bit_or(a, b) = _mm256_or_si256;
    xor(a, b) = _mm256_xor_si256;
    // |a| where b has a's sign: (a ^ m) − m with m = −1 for b < 0.
    abs_by(a, b) = |a, b| { let m = negative1(b); _mm256_sub_epi64(_mm256_xor_si256(a, m), m) };
    mul32(a, b) = _mm256_mul_epi32;
    div_f64(a, b) = div1;
    mul_lo32(a, b) = |a, b| _mm256_add_epi64(_mm256_mul_epu32(a, b), _mm256_slli_epi64::<32>(_mm256_mul_epu32(a, _mm256_srli_epi64::<32>(b))));
    sign(a) = negative1;
    // floor(a / 64) for a ≥ 0.
    div64(a) = _mm256_srli_epi64::<6>;
    // Comparisons: a mask per lane in the sign bit. a ≤ b is not a > b.
    lt(a, b) = |a, b| _mm256_cmpgt_epi64(b, a);
    le(a, b) = |a, b| _mm256_xor_si256(_mm256_cmpgt_epi64(a, b), _mm256_set1_epi64x(-1));
    ge(a, b) = |a, b| _mm256_xor_si256(_mm256_cmpgt_epi64(b, a), _mm256_set1_epi64x(-1));
    // Unsigned: both with the sign bit flipped, compared signed.
    le_unsigned(a, b) = |a, b| {
        let flip = _mm256_set1_epi64x(i64::MIN);
        _mm256_xor_si256(_mm256_cmpgt_epi64(_mm256_xor_si256(a, flip), _mm256_xor_si256(b, flip)), _mm256_set1_epi64x(-1))
    };
    // The sign bits are the mask already.
    negative(a) = |a| a;
    // The lane masks.
    both(a, b) = _mm256_and_si256;
    either(a, b) = _mm256_or_si256;
}

#[inline]
#[target_feature(enable = "avx2")]
fn splat(x: i64) -> W {
    [_mm256_set1_epi64x(x); N]
}

/// For a factor of `mul32` (which reads the low 32 bits of a lane): one broadcast.
#[inline]
#[target_feature(enable = "avx2")]
fn splat32(x: i64) -> W {
    [_mm256_set1_epi32(x as i32); N]
}

/// `b` in the lanes of `m`, `a` elsewhere.
#[inline]
#[target_feature(enable = "avx2")]
fn blend(m: Mask, a: W, b: W) -> W {
    std::array::from_fn(|i| select(m[i], a[i], b[i]))
}

/// Arithmetic right (`sra`) or logical left (`sll`) shift of every lane by `s`.
#[inline]
#[target_feature(enable = "avx2")]
fn sra(a: W, s: u32) -> W {
    let s = _mm_set_epi64x(0, s as i64);
    a.map(|x| sra1(x, s))
}

/// `sra` for |a| < 2^62, one instruction shorter: a + 2^62 is not negative, and
/// floor((a + 2^62) / 2^s) − 2^(62−s) = floor(a / 2^s).
#[inline]
#[target_feature(enable = "avx2")]
fn sra_small(a: W, s: u32) -> W {
    let (bias, back, s) = (_mm256_set1_epi64x(1 << 62), _mm256_set1_epi64x(1 << (62 - s)), _mm_set_epi64x(0, s as i64));
    a.map(|x| _mm256_sub_epi64(_mm256_srl_epi64(_mm256_add_epi64(x, bias), s), back))
}

#[inline]
#[target_feature(enable = "avx2")]
fn sll(a: W, s: u32) -> W {
    let s = _mm_set_epi64x(0, s as i64);
    a.map(|x| _mm256_sll_epi64(x, s))
}

#[inline]
#[target_feature(enable = "avx2")]
fn any(m: Mask) -> bool {
    let m = m.into_iter().reduce(|a, b| _mm256_or_si256(a, b)).unwrap_or(m[0]);
    _mm256_testz_pd(_mm256_castsi256_pd(m), _mm256_castsi256_pd(m)) == 0
}

#[inline]
#[target_feature(enable = "avx2")]
fn count(m: Mask) -> u32 {
    (0..N).fold(0, |c, i| c + (_mm256_movemask_pd(_mm256_castsi256_pd(m[i])) as u32).count_ones())
}

/// Every lane if `b`, else none.
#[inline]
#[target_feature(enable = "avx2")]
fn all_if(b: bool) -> Mask {
    splat(-(b as i64))
}

/// The first `len` lanes.
#[inline]
#[target_feature(enable = "avx2")]
fn first(len: usize) -> Mask {
    to_w(std::array::from_fn(|l| -((l < len) as i64)))
}

packet_walk!("avx2");
