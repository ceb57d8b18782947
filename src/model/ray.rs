//! World-space rays and their quantisation onto the grid (seed 001 §2.1.2).

use super::golden::{Golden, GridRay, perm};
use crate::scene::Scene;

/// A world-space ray; `d` has unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldRay {
    pub o: [f64; 3],
    pub d: [f64; 3],
}

pub fn normalize(v: [f64; 3]) -> [f64; 3] {
    let l = dot(v, v).sqrt();
    v.map(|x| x / l)
}
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|k| a[k] - b[k])
}

/// A ray prepared for the integer model, with the grid distance its origin was moved by.
#[derive(Clone, Copy, Debug)]
pub struct QuantizedRay {
    pub ray: GridRay,
    /// Grid units from the original origin to the clipped one (0 when it started inside).
    pub t_offset: f64,
}

/// Quantises a direction to m-bit fixed point: round(d · 2^F), symmetric range.
#[inline]
pub fn quantize_direction(d: [f64; 3], f: u32) -> [i64; 3] {
    let one = (1u128 << f) as f64;
    let lim = ((1i128 << f) - 1) as i64;
    let q = |x: f64| round_i64(x * one).clamp(-lim, lim);
    [q(d[0]), q(d[1]), q(d[2])]
}

/// `x.round() as i64` (halves away from zero, saturating, NaN → 0) without the libm call
/// `round` becomes on baseline x86-64. Below 2^52 the fraction x − trunc(x) is exact; from
/// there on x is an integer (fraction 0) or saturates, and the saturating add keeps that.
#[inline]
pub fn round_i64(x: f64) -> i64 {
    let i = x as i64;
    let frac = x - i as f64;
    i.saturating_add((frac >= 0.5) as i64 - (frac <= -0.5) as i64)
}

/// Clips the origin to the scene box in floating point, then rounds it to the grid and
/// quantises the direction. None when the ray misses the box entirely.
#[inline]
pub fn quantize_ray(scene: &Scene, g: &Golden, ray: &WorldRay) -> Option<QuantizedRay> {
    let o = scene.transform.to_grid_f64(ray.o);
    let hi_i = scene.grid_box.hi;
    let hi = [hi_i[0] as f64, hi_i[1] as f64, hi_i[2] as f64];
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for k in 0..3 {
        if ray.d[k] == 0.0 {
            if o[k] < 0.0 || o[k] > hi[k] {
                return None;
            }
            continue;
        }
        let (a, b) = ((0.0 - o[k]) / ray.d[k], (hi[k] - o[k]) / ray.d[k]);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    if t0 > t1 {
        return None;
    }
    // round(x).clamp(0, hi) as i64, with the clamp after the cast: both saturate alike.
    let origin = |k: usize| round_i64(o[k] + t0 * ray.d[k]).clamp(0, hi_i[k]);
    let origin = [origin(0), origin(1), origin(2)];
    let w = quantize_direction(ray.d, g.f);
    if w == [0; 3] {
        return None;
    }
    Some(QuantizedRay { ray: g.ray(origin, w), t_offset: t0 })
}

/// A grid ray in the i64 form the fast path of `Golden::trace_fast` reads (its bounds are
/// proved in golden.rs): rows[r] = [O_r, O_p, O_q, ω_r, ω_p, ω_q] for projection axis r.
pub(crate) struct NarrowRay {
    pub(crate) rows: [[i64; 6]; 4],
    pub(crate) axes: [NarrowAxis; 3],
    /// `Golden::box_exit`.
    pub(crate) tmax0: i64,
}

/// One axis for plane distances: inv = inv_hi·2^C + inv_lo with 0 ≤ inv_lo < 2^C, so
/// floor((P − O)·inv / 2^C) = (P − O)·inv_hi + floor((P − O)·inv_lo / 2^C), all in i64.
pub(crate) struct NarrowAxis {
    pub(crate) o: i64,
    pub(crate) inv_hi: i64,
    pub(crate) inv_lo: i64,
    /// inv < 0: the right child (link + 1) is the near one.
    pub(crate) neg: bool,
}

impl NarrowAxis {
    /// `Golden::plane_t` before saturation, for a plane in [0, 2^n).
    #[inline(always)]
    pub(crate) fn plane_t(&self, plane: i64, c: u32) -> i64 {
        let d = plane - self.o;
        d * self.inv_hi + ((d * self.inv_lo) >> c)
    }
}

impl NarrowRay {
    /// The ray is inside the bounds of the fast path: 0 ≤ O < 2^n, |ω| < 2^F and |inv| <
    /// 2^(F+C) (what `Golden::ray` makes; < 2^63 as m + C ≤ 64).
    #[inline]
    pub(crate) fn fits(g: &Golden, ray: &GridRay) -> bool {
        ray.o.iter().all(|&o| (0..1i64 << g.n).contains(&o))
            && ray.w.iter().all(|&w| w.unsigned_abs() < 1 << g.f)
            && ray.inv.iter().all(|&i| i.unsigned_abs() < 1 << (g.f + g.c))
    }

    /// None when the ray does not fit.
    pub(crate) fn new(g: &Golden, ray: &GridRay) -> Option<NarrowRay> {
        if !Self::fits(g, ray) {
            return None;
        }
        let axes: [NarrowAxis; 3] = std::array::from_fn(|k| {
            let inv = ray.inv[k] as i64;
            NarrowAxis { o: ray.o[k], inv_hi: inv >> g.c, inv_lo: inv & ((1 << g.c) - 1), neg: inv < 0 }
        });
        let exit = |k: usize| axes[k].plane_t(if axes[k].neg { 0 } else { g.box_hi[k] }, g.c).clamp(-1, g.t_sat);
        let rows = std::array::from_fn(|r| {
            let (r, p, q) = perm(r as u8 % 3);
            [ray.o[r], ray.o[p], ray.o[q], ray.w[r], ray.w[p], ray.w[q]]
        });
        Some(NarrowRay { rows, tmax0: exit(0).min(exit(1)).min(exit(2)), axes })
    }
}

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
    use crate::params::Params;
    use crate::scene::SceneSource;

    fn cube_scene() -> Scene {
        let t = vec![[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], [[0., 0., 1.], [1., 1., 1.], [1., 0., 1.]]];
        Scene::build("cube", t, &Params::default()).unwrap()
    }

    proptest::proptest! {
        #[test]
        fn round_i64_is_round_as_i64(bits in proptest::num::u64::ANY, small in -1e6f64..1e6, k in 0i64..1 << 53) {
            for x in [f64::from_bits(bits), small, k as f64 + 0.5, -(k as f64) - 0.5, (k as f64 + 0.5).next_down(), k as f64 * 4096.0] {
                proptest::prop_assert_eq!(round_i64(x), x.round() as i64, "{}", x);
            }
        }
    }

    proptest::proptest! {
        /// The split plane distance and box exit of `NarrowRay` are `plane_t` and `box_exit`.
        #[test]
        fn narrow_planes_are_plane_t(
            set in 0usize..3,
            o in proptest::array::uniform3(0.0f64..1.0),
            w in proptest::array::uniform3(-1.0f64..1.0),
            plane in 0.0f64..1.0,
            k in 0usize..3,
        ) {
            let (n, m, c) = [(29, 32, 16), (40, 21, 3), (16, 16, 46)][set];
            let params = Params { n, m, c, ..Params::default() };
            let s = Scene::build("cube", vec![[[0., 0., 0.], [1., 0., 0.], [0., 1., 1.]]], &params).unwrap();
            let g = Golden::new(&s);
            let b = (1i64 << g.n) as f64;
            let ray = g.ray(o.map(|x| (x * b) as i64), quantize_direction(w, g.f));
            let nr = NarrowRay::new(&g, &ray).unwrap();
            let plane = (plane * b) as i64;
            proptest::prop_assert_eq!(nr.axes[k].plane_t(plane, g.c).clamp(-1, g.t_sat), g.plane_t(&ray, k, plane));
            proptest::prop_assert_eq!(nr.tmax0, g.box_exit(&ray));
        }
    }

    #[test]
    fn round_i64_edges() {
        let big = [
            2f64.powi(52) + 1.0,
            2f64.powi(63),
            -2f64.powi(63),
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            1e300,
            -1e300,
        ];
        for x in [0.0, -0.0, 0.5, -0.5, 0.49999999999999994].into_iter().chain(big) {
            assert_eq!(round_i64(x), x.round() as i64, "{x}");
        }
    }

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

    #[test]
    fn outside_origin_is_clipped_to_the_box() {
        let s = cube_scene();
        let g = Golden::new(&s);
        let q = quantize_ray(&s, &g, &WorldRay { o: [0.25, 0.25, -1.0], d: [0.0, 0.0, 1.0] }).unwrap();
        let g0 = crate::scene::GUARD as f64;
        let span = ((1i64 << 29) - 1) as f64 - 2.0 * g0;
        let quarter = (g0 + 0.25 * span).round() as i64;
        assert_eq!(q.ray.o, [quarter, quarter, 0]);
        // From world z = −1 to the grid box face, which lies GUARD units before the scene.
        assert!((q.t_offset - (span - g0)).abs() < 1e-6);
        assert_eq!(q.ray.w, [0, 0, (1i64 << 31) - 1]);
        assert!(quantize_ray(&s, &g, &WorldRay { o: [2.0, 2.0, -1.0], d: [0.0, 0.0, 1.0] }).is_none());
        assert!(quantize_ray(&s, &g, &WorldRay { o: [0.5, 0.5, -1.0], d: [0.0, 0.0, -1.0] }).is_none());
    }
}
