//! `quantize_ray` of eight rays at once with AVX-512 (for `GoldenTracer::primary_row`).

use crate::model::golden::Golden;
use crate::model::ray::{QuantizedRay, WorldRay};
use crate::scene::Scene;

/// `quantize_ray` of eight rays at once, calling `inside(i, quantized)` for each that reaches
/// the box; false (and no call) unless the CPU has AVX-512 (F, DQ), F + C ≤ 50 (for the
/// reciprocal) and the rays are eight, with finite origins and directions and no zero
/// direction component.
pub(crate) fn quantize_ray8(
    scene: &Scene,
    g: &Golden,
    rays: &[WorldRay],
    inside: &mut impl FnMut(usize, QuantizedRay),
) -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        let finite = |v: &[f64; 3]| v.iter().all(|x| x.is_finite());
        let cpu = is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512dq");
        if cpu
            && g.f + g.c <= 50
            && rays.len() == 8
            && rays.iter().all(|r| finite(&r.o) && finite(&r.d) && !r.d.contains(&0.0))
        {
            // SAFETY: the CPU has AVX-512F and DQ (checked above).
            unsafe { avx512::quantize_ray8(scene, g, rays, inside) };
            return true;
        }
    }
    let _ = (scene, g, rays, inside);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::ray::{normalize, quantize_ray};
    use crate::params::Params;
    use crate::scene::SceneSource;

    /// `quantize_ray8` gives `quantize_ray`'s grid ray (and t0, up to the sign of a zero)
    /// for rays from inside, outside and far outside the box, including nearly axis-parallel
    /// directions and directions that round to zero.
    #[test]
    fn quantize_ray8_is_quantize_ray() {
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
            if !quantize_ray8(&scene, &g, &rays, &mut |l, q| got[l] = Some(q)) {
                continue;
            }
            for (ray, got) in rays.iter().zip(got) {
                let want = quantize_ray(&scene, &g, ray);
                assert_eq!(got.map(|q| (q.ray, q.t_offset)), want.map(|q| (q.ray, q.t_offset)), "{ray:?}");
                (compared, inside) = (compared + 1, inside + want.is_some() as u32);
            }
        }
        let simd = quantize_ray8(&scene, &g, &[WorldRay { o: [0.0; 3], d: [1.0; 3] }; 8], &mut |_, _| ());
        assert!(!simd || (compared == 160000 && inside > 10000 && inside < 150000), "{compared} {inside}");
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
            if !quantize_ray8(&scene, &g, &rays, &mut |l, q| got[l] = Some(q)) {
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
        assert!(!simd || ties > 40000, "{ties} halfway origins");
    }
}
