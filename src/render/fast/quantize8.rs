//! `quantize_ray` of eight rays at once with AVX-512 or AVX2 (for `GoldenTracer::primary_row`).

use crate::model::golden::Golden;
use crate::model::ray::{QuantizedRay, WorldRay};
use crate::render::fast::Kernel;
use crate::scene::Scene;

/// `quantize_ray` of eight rays at once on `kernel`'s instructions, calling `inside(i,
/// quantized)` for each that reaches the box; false (and no call) unless the CPU has them,
/// F + C ≤ 50 (for the reciprocal) and the rays are eight, with finite origins and directions
/// and no zero direction component.
pub(crate) fn quantize_ray8(
    scene: &Scene,
    g: &Golden,
    kernel: Kernel,
    rays: &[WorldRay],
    inside: &mut impl FnMut(usize, QuantizedRay),
) -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        let finite = |v: &[f64; 3]| v.iter().all(|x| x.is_finite());
        if kernel.cpu_has()
            && g.f + g.c <= 50
            && rays.len() == 8
            && rays.iter().all(|r| finite(&r.o) && finite(&r.d) && !r.d.contains(&0.0))
        {
            match kernel {
                // SAFETY: the CPU has AVX-512F and DQ (checked above).
                Kernel::Avx512 => unsafe { avx512::quantize_ray8(scene, g, rays, inside) },
                // SAFETY: the CPU has AVX2 (checked above).
                Kernel::Avx2 => unsafe { avx2::quantize_ray8(scene, g, rays, inside) },
            }
            return true;
        }
    }
    let _ = (scene, g, kernel, rays, inside);
    false
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use super::{QuantizedRay, WorldRay};
    use crate::model::golden::{Golden, GridRay};
    use crate::scene::Scene;
    use std::arch::x86_64::*;

    /// The same f64 operations as `quantize_ray` in the same order, so the same values: IEEE
    /// division, products and sums are the same in a vector, and min and max can differ only
    /// in the sign of a zero, which changes nothing (t0 moves the origin by t0·ω and is added
    /// to a t ≥ 1). Rounding clamps to ±2^62 first, where `round_i64` and the clamp to the box
    /// agree; the reciprocal is `div_floor`'s f64 quotient, exact for 2^(F+C) ≤ 2^50.
    #[target_feature(enable = "avx512f,avx512dq")]
    pub(super) fn quantize_ray8(
        scene: &Scene,
        g: &Golden,
        rays: &[WorldRay],
        inside: &mut impl FnMut(usize, QuantizedRay),
    ) {
        let (mut org, mut dir) = ([[0.0; 8]; 3], [[0.0; 8]; 3]);
        for (l, r) in rays.iter().enumerate() {
            for k in 0..3 {
                (org[k][l], dir[k][l]) = (r.o[k], r.d[k]);
            }
        }
        // SAFETY: [f64; 8] and __m512d are both 64 bytes of plain f64.
        let (org, d): ([__m512d; 3], [__m512d; 3]) = unsafe { std::mem::transmute((org, dir)) };
        let splat = _mm512_set1_pd;
        let (tf, hi_i) = (&scene.transform, scene.grid_box.hi);
        let o: [__m512d; 3] =
            std::array::from_fn(|k| _mm512_mul_pd(_mm512_sub_pd(org[k], splat(tf.min[k])), splat(tf.scale)));
        let (mut t0, mut t1) = (splat(0.0), splat(f64::INFINITY));
        for k in 0..3 {
            let a = _mm512_div_pd(_mm512_sub_pd(splat(0.0), o[k]), d[k]);
            let b = _mm512_div_pd(_mm512_sub_pd(splat(hi_i[k] as f64), o[k]), d[k]);
            t0 = _mm512_max_pd(t0, _mm512_min_pd(a, b));
            t1 = _mm512_min_pd(t1, _mm512_max_pd(a, b));
        }
        let round = |x: __m512d| {
            let big = (1u64 << 62) as f64;
            let x = _mm512_min_pd(_mm512_max_pd(x, splat(-big)), splat(big));
            let i = _mm512_cvttpd_epi64(x);
            let frac = _mm512_sub_pd(x, _mm512_cvtepi64_pd(i));
            let up = _mm512_maskz_mov_epi64(_mm512_cmp_pd_mask::<_CMP_GE_OQ>(frac, splat(0.5)), _mm512_set1_epi64(1));
            let down =
                _mm512_maskz_mov_epi64(_mm512_cmp_pd_mask::<_CMP_LE_OQ>(frac, splat(-0.5)), _mm512_set1_epi64(1));
            _mm512_sub_epi64(_mm512_add_epi64(i, up), down)
        };
        let clamp = |x: __m512i, lo: i64, hi: i64| {
            _mm512_min_epi64(_mm512_max_epi64(x, _mm512_set1_epi64(lo)), _mm512_set1_epi64(hi))
        };
        let origin: [__m512i; 3] =
            std::array::from_fn(|k| clamp(round(_mm512_add_pd(o[k], _mm512_mul_pd(t0, d[k]))), 0, hi_i[k]));
        let lim = (1i64 << g.f) - 1;
        let w: [__m512i; 3] =
            std::array::from_fn(|k| clamp(round(_mm512_mul_pd(d[k], splat((1u64 << g.f) as f64))), -lim, lim));
        // reciprocal: ω = 0 as +1, trunc(2^s / ω) = sign(ω)·floor(2^s / |ω|), saturated.
        let (s, lim_inv) = (1i64 << (g.f + g.c), (1i64 << (g.f + g.c)) - 1);
        let inv: [__m512i; 3] = std::array::from_fn(|k| {
            let w = _mm512_mask_mov_epi64(
                w[k],
                _mm512_cmpeq_epi64_mask(w[k], _mm512_setzero_si512()),
                _mm512_set1_epi64(1),
            );
            let a = _mm512_abs_epi64(w);
            let q = _mm512_cvttpd_epi64(_mm512_div_pd(splat(s as f64), _mm512_cvtepi64_pd(a)));
            let r = _mm512_sub_epi64(_mm512_set1_epi64(s), _mm512_mullo_epi64(q, a));
            let up = _mm512_maskz_mov_epi64(_mm512_cmpge_epi64_mask(r, a), _mm512_set1_epi64(1));
            let q = _mm512_add_epi64(_mm512_add_epi64(q, _mm512_srai_epi64::<63>(r)), up);
            let q = _mm512_mask_sub_epi64(q, _mm512_movepi64_mask(w), _mm512_setzero_si512(), q);
            clamp(q, -lim_inv, lim_inv)
        });
        let zero = |v: __m512i| _mm512_cmpeq_epi64_mask(v, _mm512_setzero_si512());
        let hits_box = !_mm512_cmp_pd_mask::<_CMP_GT_OQ>(t0, t1) & !(zero(w[0]) & zero(w[1]) & zero(w[2]));
        type Lanes = [[i64; 8]; 3];
        // SAFETY: as above, for i64 and f64 lanes.
        let (origin, w, inv, t0): (Lanes, Lanes, Lanes, [f64; 8]) =
            unsafe { std::mem::transmute((origin, w, inv, t0)) };
        for l in (0..8).filter(|l| hits_box >> l & 1 == 1) {
            let ray = GridRay { o: origin.map(|v| v[l]), w: w.map(|v| v[l]), inv: inv.map(|v| v[l] as i128) };
            inside(l, QuantizedRay { ray, t_offset: t0[l] });
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{QuantizedRay, WorldRay};
    use crate::model::golden::{Golden, GridRay};
    use crate::scene::Scene;
    use std::arch::x86_64::*;

    /// As the AVX-512 version, four rays to a register. AVX2 has no f64 → i64 conversion:
    /// `to_i64` reads an integer-valued |x| < 2^51 from the bits of x + 1.5·2^52 (exact), and
    /// rounding clamps to ±2^50 first, which changes no result after the clamps to the box
    /// (< 2^n ≤ 2^40) and to ±(2^F − 1) (F ≤ 50 − C).
    #[target_feature(enable = "avx2")]
    pub(super) fn quantize_ray8(
        scene: &Scene,
        g: &Golden,
        rays: &[WorldRay],
        inside: &mut impl FnMut(usize, QuantizedRay),
    ) {
        let (mut org, mut dir) = ([[[0.0; 4]; 3]; 2], [[[0.0; 4]; 3]; 2]);
        for (l, r) in rays.iter().enumerate() {
            for k in 0..3 {
                (org[l / 4][k][l % 4], dir[l / 4][k][l % 4]) = (r.o[k], r.d[k]);
            }
        }
        // Both halves computed before any ray is handed on, so that their divisions overlap.
        type Half = ([__m256d; 3], [__m256d; 3]);
        // SAFETY: [f64; 4] and __m256d are both 32 bytes of plain f64.
        let half = |h: usize| unsafe { std::mem::transmute::<([[f64; 4]; 3], [[f64; 4]; 3]), Half>((org[h], dir[h])) };
        let halves: [Quantized4; 2] = std::array::from_fn(|h| quantize_ray4(scene, g, half(h)));
        for (h, q) in halves.iter().enumerate() {
            for l in (0..4).filter(|l| q.misses >> l & 1 == 0) {
                let ray = GridRay { o: q.origin.map(|v| v[l]), w: q.w.map(|v| v[l]), inv: q.inv.map(|v| v[l] as i128) };
                inside(4 * h + l, QuantizedRay { ray, t_offset: q.t0[l] });
            }
        }
    }

    type Lanes = [[i64; 4]; 3];

    /// Four rays quantised: a bit of `misses` for each that misses the box.
    struct Quantized4 {
        origin: Lanes,
        w: Lanes,
        inv: Lanes,
        t0: [f64; 4],
        misses: i32,
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    fn quantize_ray4(scene: &Scene, g: &Golden, (org, d): ([__m256d; 3], [__m256d; 3])) -> Quantized4 {
        let splat = _mm256_set1_pd;
        let (tf, hi_i) = (&scene.transform, scene.grid_box.hi);
        let o: [__m256d; 3] =
            std::array::from_fn(|k| _mm256_mul_pd(_mm256_sub_pd(org[k], splat(tf.min[k])), splat(tf.scale)));
        let (mut t0, mut t1) = (splat(0.0), splat(f64::INFINITY));
        for k in 0..3 {
            let a = _mm256_div_pd(_mm256_sub_pd(splat(0.0), o[k]), d[k]);
            let b = _mm256_div_pd(_mm256_sub_pd(splat(hi_i[k] as f64), o[k]), d[k]);
            t0 = _mm256_max_pd(t0, _mm256_min_pd(a, b));
            t1 = _mm256_min_pd(t1, _mm256_max_pd(a, b));
        }
        let magic = splat(1.5 * 2f64.powi(52));
        let to_i64 =
            |x: __m256d| _mm256_sub_epi64(_mm256_castpd_si256(_mm256_add_pd(x, magic)), _mm256_castpd_si256(magic));
        // round_i64: trunc(x) + (frac ≥ 1/2) − (frac ≤ −1/2); NaN becomes −2^50 (max_pd gives
        // its second operand), which clamps to what round_i64's 0 clamps to.
        let round = |x: __m256d| {
            let big = 2f64.powi(50);
            let x = _mm256_min_pd(_mm256_max_pd(x, splat(-big)), splat(big));
            let i = _mm256_round_pd::<{ _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC }>(x);
            let frac = _mm256_sub_pd(x, i);
            let up = _mm256_castpd_si256(_mm256_cmp_pd::<_CMP_GE_OQ>(frac, splat(0.5)));
            let down = _mm256_castpd_si256(_mm256_cmp_pd::<_CMP_LE_OQ>(frac, splat(-0.5)));
            // The masks are −1 where true.
            _mm256_add_epi64(_mm256_sub_epi64(to_i64(i), up), down)
        };
        let clamp = |x: __m256i, lo: i64, hi: i64| {
            let (lo, hi) = (_mm256_set1_epi64x(lo), _mm256_set1_epi64x(hi));
            let x = _mm256_blendv_epi8(x, lo, _mm256_cmpgt_epi64(lo, x));
            _mm256_blendv_epi8(x, hi, _mm256_cmpgt_epi64(x, hi))
        };
        let origin: [__m256i; 3] =
            std::array::from_fn(|k| clamp(round(_mm256_add_pd(o[k], _mm256_mul_pd(t0, d[k]))), 0, hi_i[k]));
        let lim = (1i64 << g.f) - 1;
        let w: [__m256i; 3] =
            std::array::from_fn(|k| clamp(round(_mm256_mul_pd(d[k], splat((1u64 << g.f) as f64))), -lim, lim));
        // reciprocal: ω = 0 as +1, trunc(2^s / ω) = sign(ω)·floor(2^s / |ω|), saturated. The
        // quotient is below 2^50 and |ω| < 2^31, so q·|ω| is a 32 × 64-bit product.
        let (s, lim_inv) = (1i64 << (g.f + g.c), (1i64 << (g.f + g.c)) - 1);
        let zero = _mm256_setzero_si256();
        let inv: [__m256i; 3] = std::array::from_fn(|k| {
            let w = _mm256_blendv_epi8(w[k], _mm256_set1_epi64x(1), _mm256_cmpeq_epi64(w[k], zero));
            let neg = _mm256_cmpgt_epi64(zero, w);
            let a = _mm256_sub_epi64(_mm256_xor_si256(w, neg), neg);
            let a_f = _mm256_sub_pd(_mm256_castsi256_pd(_mm256_add_epi64(a, _mm256_castpd_si256(magic))), magic);
            let q = to_i64(_mm256_round_pd::<{ _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC }>(_mm256_div_pd(
                splat(s as f64),
                a_f,
            )));
            let qa = _mm256_add_epi64(
                _mm256_mul_epu32(a, q),
                _mm256_slli_epi64::<32>(_mm256_mul_epu32(a, _mm256_srli_epi64::<32>(q))),
            );
            let r = _mm256_sub_epi64(_mm256_set1_epi64x(s), qa);
            // q − 1 when r < 0, q + 1 when r ≥ |ω| (the masks are −1 where true).
            let up = _mm256_xor_si256(_mm256_cmpgt_epi64(a, r), _mm256_set1_epi64x(-1));
            let q = _mm256_add_epi64(_mm256_sub_epi64(q, up), _mm256_cmpgt_epi64(zero, r));
            clamp(_mm256_sub_epi64(_mm256_xor_si256(q, neg), neg), -lim_inv, lim_inv)
        });
        let zero_w = |v: __m256i| _mm256_cmpeq_epi64(v, zero);
        let all_zero = _mm256_and_si256(_mm256_and_si256(zero_w(w[0]), zero_w(w[1])), zero_w(w[2]));
        let past = _mm256_castpd_si256(_mm256_cmp_pd::<_CMP_GT_OQ>(t0, t1));
        let misses = _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_or_si256(past, all_zero)));
        // SAFETY: as above, for i64 and f64 lanes.
        let (origin, w, inv, t0): (Lanes, Lanes, Lanes, [f64; 4]) =
            unsafe { std::mem::transmute((origin, w, inv, t0)) };
        Quantized4 { origin, w, inv, t0, misses }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::ray::{normalize, quantize_ray};
    use crate::params::Params;
    use crate::scene::SceneSource;

    /// `quantize_ray8` gives `quantize_ray`'s grid ray (and t0, up to the sign of a zero)
    /// for rays from inside, outside and far outside the box, including nearly axis-parallel
    /// directions and directions that round to zero, on each instruction set this CPU has.
    #[test]
    fn quantize_ray8_is_quantize_ray() {
        for kernel in [Kernel::Avx512, Kernel::Avx2] {
            if kernel.cpu_has() {
                quantize_ray8_matches(kernel);
            } else {
                // Past the test harness's capture: a skipped path is worth seeing in every run.
                use std::io::Write;
                let _ = writeln!(std::io::stderr().lock(), "skipped: quantize_ray8 on {kernel:?}: not on this CPU");
            }
        }
    }

    fn quantize_ray8_matches(kernel: Kernel) {
        let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &Params::default()).unwrap();
        let g = Golden::new(&scene);
        let (lo, hi) = crate::model::camera::world_bounds(&scene);
        let mut seed = 3u64;
        let mut rand = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut compared, mut inside) = (0, 0);
        for _ in 0..20000 {
            let rays: Vec<WorldRay> = (0..8)
                .map(|_| {
                    let spread = [0.5, 3.0, 1e6][(rand() * 3.0) as usize];
                    let o = std::array::from_fn(|k| lo[k] + (hi[k] - lo[k]) * (0.5 + spread * (rand() - 0.5)));
                    let tiny = [1.0, 1e-9, 1e-300][(rand() * 3.0) as usize];
                    WorldRay { o, d: normalize([rand() - 0.5, (rand() - 0.5) * tiny, rand() - 0.5]) }
                })
                .collect();
            let mut got = [None; 8];
            if !quantize_ray8(&scene, &g, kernel, &rays, &mut |l, q| got[l] = Some(q)) {
                continue;
            }
            for (ray, got) in rays.iter().zip(got) {
                let want = quantize_ray(&scene, &g, ray);
                assert_eq!(got.map(|q| (q.ray, q.t_offset)), want.map(|q| (q.ray, q.t_offset)), "{ray:?}");
                (compared, inside) = (compared + 1, inside + want.is_some() as u32);
            }
        }
        let simd = quantize_ray8(&scene, &g, kernel, &[WorldRay { o: [0.0; 3], d: [1.0; 3] }; 8], &mut |_, _| ());
        assert!(simd && compared == 160000 && inside > 10000 && inside < 150000, "{kernel:?}: {compared} {inside}");
        // Halfway cases of the two roundings: origins inside the box at k + 1/2 grid units
        // (t0 = 0), directions at j + 1/2 units of 2^−F.
        let (tf, one) = (scene.transform, (1u64 << g.f) as f64);
        let mut ties = 0;
        for _ in 0..4000 {
            let rays: Vec<WorldRay> = (0..8)
                .map(|_| {
                    let o = std::array::from_fn(|k| {
                        let x = (1.0 + (rand() * (scene.grid_box.hi[k] - 2) as f64).floor()) + 0.5;
                        let w = tf.min[k] + x / tf.scale;
                        [w, w.next_up(), w.next_down()]
                            .into_iter()
                            .find(|w| (w - tf.min[k]) * tf.scale == x)
                            .unwrap_or(w)
                    });
                    let d = std::array::from_fn(|_| {
                        ((rand() * (one - 2.0)).floor() + 0.5) / one * if rand() < 0.5 { -1.0 } else { 1.0 }
                    });
                    WorldRay { o, d }
                })
                .collect();
            let mut got = [None; 8];
            if !quantize_ray8(&scene, &g, kernel, &rays, &mut |l, q| got[l] = Some(q)) {
                continue;
            }
            for (ray, got) in rays.iter().zip(got) {
                assert_eq!(
                    got.map(|q| (q.ray, q.t_offset)),
                    quantize_ray(&scene, &g, ray).map(|q| (q.ray, q.t_offset)),
                    "{ray:?}"
                );
                ties += tf.to_grid_f64(ray.o).iter().filter(|x| x.fract() == 0.5).count();
            }
        }
        assert!(simd && ties > 40000, "{kernel:?}: {ties} halfway origins");
    }
}
