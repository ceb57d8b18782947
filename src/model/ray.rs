//! World-space rays and their quantisation onto the grid (seed 001 §2.1.2).

use super::golden::{Golden, GridRay};
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;

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
