//! Floating-point reference implementations used to validate the fixed-point
//! tracer: the Badouel/Wald projected triangle test (same formulas as the
//! integer design, Hanika 2007 eq. 2.1/2.2), pbrt's watertight ray/triangle
//! test (PBR 3rd ed. §3.6.2 / §3.9) and a ray/box slab test.

use core::fmt::Debug;
use core::ops::{Add, Div, Mul, Neg, Sub};

/// The few float operations the generic tests need, implemented for f32 and f64.
pub trait Real:
    Copy
    + Debug
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Default
    + Send
    + Sync
    + 'static
{
    fn from_f64(x: f64) -> Self;
    fn to_f64(self) -> f64;
    fn abs(self) -> Self;
    fn zero() -> Self;
    fn one() -> Self;
    fn max_value() -> Self;
    fn infinity() -> Self;
}

macro_rules! impl_real {
    ($t:ident) => {
        impl Real for $t {
            fn from_f64(x: f64) -> Self {
                x as $t
            }
            fn to_f64(self) -> f64 {
                self as f64
            }
            fn abs(self) -> Self {
                $t::abs(self)
            }
            fn zero() -> Self {
                0.0
            }
            fn one() -> Self {
                1.0
            }
            fn max_value() -> Self {
                $t::MAX
            }
            fn infinity() -> Self {
                $t::INFINITY
            }
        }
    };
}
impl_real!(f32);
impl_real!(f64);

fn sub3<F: Real>(a: [F; 3], b: [F; 3]) -> [F; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross<F: Real>(a: [F; 3], b: [F; 3]) -> [F; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Smallest index of the largest |a_k| (ties go to the lower axis, as in the integer design).
fn argmax_abs<F: Real>(a: [F; 3]) -> usize {
    (1..3).fold(0, |k, i| if a[i].abs() > a[k].abs() { i } else { k })
}

fn max_abs<F: Real>(a: [F; 3]) -> F {
    a.iter().fold(F::zero(), |m, x| if x.abs() > m { x.abs() } else { m })
}

/// Badouel/Wald accelerated triangle: the plane and the edges are stored
/// pre-divided by the dominant normal component `n_r`, so the test projects
/// onto the (p, q) plane with p = (r+1)%3, q = (r+2)%3.
///
/// Why `u` is the weight of x2 and `v` the weight of x1: with b = x1−x0,
/// c = x2−x0, a hit h = x0 + β·b + γ·c projects to k = (h−x0) restricted to
/// (p, q), i.e. k_p = β b_p + γ c_p and k_q = β b_q + γ c_q. Because (r, p, q)
/// is a cyclic permutation of (x, y, z), n_r = (b×c)_r = b_p c_q − b_q c_p is
/// the determinant of that 2×2 system, and Cramer's rule gives
/// γ = (b_p k_q − b_q k_p)/n_r = e1p·k_q − e1q·k_p = u (weight of x2) and
/// β = (c_q k_p − c_p k_q)/n_r = e2q·k_p − e2p·k_q = v (weight of x1).
#[derive(Clone, Copy, Debug)]
pub struct FloatTri<F> {
    pub r: u8,
    pub pp: F,
    pub pq: F,
    pub d: F,
    pub np: F,
    pub nq: F,
    pub e1p: F,
    pub e1q: F,
    pub e2p: F,
    pub e2q: F,
}

impl<F: Real> FloatTri<F> {
    /// None if degenerate (n_r == 0 in this float type, or NaN).
    pub fn new(v: [[F; 3]; 3]) -> Option<Self> {
        let [x0, x1, x2] = v;
        let b = sub3(x1, x0);
        let c = sub3(x2, x0);
        let n = cross(b, c);
        let r = argmax_abs(n);
        let nr = n[r];
        // Written as a positive test so that a NaN normal is also rejected.
        let nondegenerate = nr.abs() > F::zero();
        if !nondegenerate {
            return None;
        }
        let (p, q) = ((r + 1) % 3, (r + 2) % 3);
        let (np, nq) = (n[p] / nr, n[q] / nr);
        Some(Self {
            r: r as u8,
            pp: x0[p],
            pq: x0[q],
            d: x0[r] + x0[p] * np + x0[q] * nq,
            np,
            nq,
            e1p: b[p] / nr,
            e1q: b[q] / nr,
            e2p: c[p] / nr,
            e2q: c[q] / nr,
        })
    }

    /// Ray (origin o, direction w) against the triangle. Returns Some((t, u, v))
    /// when t_min < t < t_max and u >= 0, v >= 0, u + v <= 1, where u is the
    /// barycentric weight of x2 and v that of x1 (see the type's doc).
    pub fn intersect(&self, o: [F; 3], w: [F; 3], t_min: F, t_max: F) -> Option<(F, F, F)> {
        // Clamp so a hand-built `FloatTri` with r > 2 cannot make indexing panic.
        let r = (self.r as usize).min(2);
        let (p, q) = ((r + 1) % 3, (r + 2) % 3);
        let den = w[r] + w[p] * self.np + w[q] * self.nq;
        if den == F::zero() {
            return None; // ray parallel to the plane
        }
        let t = (self.d - o[r] - o[p] * self.np - o[q] * self.nq) / den;
        // Positive tests throughout: any NaN ends up as a miss.
        if !(t > t_min && t < t_max) {
            return None;
        }
        let kp = o[p] + t * w[p] - self.pp;
        let kq = o[q] + t * w[q] - self.pq;
        let u = self.e1p * kq - self.e1q * kp;
        let v = self.e2q * kp - self.e2p * kq;
        let zero = F::zero();
        (u >= zero && v >= zero && u + v <= F::one()).then_some((t, u, v))
    }
}

/// pbrt's γ_n = n·ε/(1 − n·ε) with ε = f32::EPSILON/2 (unit roundoff).
fn gamma(n: f32) -> f32 {
    let eps = f32::EPSILON * 0.5;
    n * eps / (1.0 - n * eps)
}

/// Watertight ray/triangle test (Woop et al. 2013 as presented in PBR 3rd ed.
/// §3.6.2, with the §3.9.6 error bound on t). Only hits with
/// 0 < t < t_max are reported (t is conservatively required to exceed its
/// rounding error bound). Returns Some((t, b0, b1, b2)) with barycentrics of
/// v0, v1, v2.
pub fn watertight_f32(o: [f32; 3], d: [f32; 3], v: [[f32; 3]; 3], t_max: f32) -> Option<(f32, f32, f32, f32)> {
    // Ray space: origin at 0, the dominant direction axis becomes z. The
    // permutation is cyclic so handedness (and thus edge signs) is preserved.
    let kz = argmax_abs(d);
    let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
    let perm = |a: [f32; 3]| [a[kx], a[ky], a[kz]];
    let dp = perm(d);
    if dp[2] == 0.0 {
        return None; // zero (or NaN) direction
    }
    // Shear so the direction becomes +z. The z scale is deferred until it is
    // needed for t, since x and y alone decide hit/miss.
    let sx = -dp[0] / dp[2];
    let sy = -dp[1] / dp[2];
    let sz = 1.0 / dp[2];
    // Each vertex is transformed by the same operations whatever triangle it
    // belongs to: this is what makes shared edges consistent.
    let p = v.map(|x| {
        let t = perm(sub3(x, o));
        [t[0] + sx * t[2], t[1] + sy * t[2], t[2]]
    });

    // Edge functions at the ray (0, 0); e_i is opposite vertex i. Swapping a and
    // b negates a·b' − a'·b exactly in IEEE arithmetic, so the neighbouring
    // triangle sees exactly the opposite sign on a shared edge.
    let edge = |a: [f32; 3], b: [f32; 3]| a[0] * b[1] - a[1] * b[0];
    let mut e = [edge(p[1], p[2]), edge(p[2], p[0]), edge(p[0], p[1])];
    if e.contains(&0.0) {
        // A 0.0 may be a tiny value lost to rounding. A product of two f32 is
        // exact in f64, so the f64 difference is rounded only once and has the
        // true sign.
        let edge64 = |a: [f32; 3], b: [f32; 3]| (a[0] as f64 * b[1] as f64 - a[1] as f64 * b[0] as f64) as f32;
        e = [edge64(p[1], p[2]), edge64(p[2], p[0]), edge64(p[0], p[1])];
    }
    let any_neg = e.iter().any(|&x| x < 0.0);
    let any_pos = e.iter().any(|&x| x > 0.0);
    if any_neg && any_pos {
        return None;
    }
    let det = e[0] + e[1] + e[2];

    // t = Σ e_i z_i / det; test the range on the unnormalised value to avoid
    // the division on misses.
    let z = [p[0][2] * sz, p[1][2] * sz, p[2][2] * sz];
    let t_scaled = e[0] * z[0] + e[1] * z[1] + e[2] * z[2];
    let in_range = if det > 0.0 {
        t_scaled > 0.0 && t_scaled <= t_max * det
    } else if det < 0.0 {
        t_scaled < 0.0 && t_scaled >= t_max * det
    } else {
        false // det == 0 (all edges zero: the ray sees the triangle edge-on) or NaN
    };
    if !in_range {
        return None;
    }
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;

    // Conservative bound on the rounding error of t (PBR §3.9.6): reject hits
    // that could really lie behind the origin.
    let max_z = max_abs(z);
    let max_x = max_abs([p[0][0], p[1][0], p[2][0]]);
    let max_y = max_abs([p[0][1], p[1][1], p[2][1]]);
    let delta_z = gamma(3.0) * max_z;
    let delta_x = gamma(5.0) * (max_x + max_z);
    let delta_y = gamma(5.0) * (max_y + max_z);
    let delta_e = 2.0 * (gamma(2.0) * max_x * max_y + delta_y * max_x + delta_x * max_y);
    let max_e = max_abs(e);
    let delta_t = 3.0 * (gamma(3.0) * max_e * max_z + delta_e * max_z + delta_z * max_e) * inv_det.abs();
    (t > delta_t && t < t_max).then(|| (t, e[0] * inv_det, e[1] * inv_det, e[2] * inv_det))
}

/// Slab test of a ray against the box [lo, hi], clipped to [t_min, t_max].
/// Returns the (entry, exit) interval, closed (grazing a face counts).
/// Axes with an infinite `inv_d` (ray parallel to the slab) are decided by the
/// origin's position, since (lo − o)·inv_d would be 0·∞ = NaN when o lies on
/// the slab plane.
pub fn ray_box<F: Real>(o: [F; 3], inv_d: [F; 3], lo: [F; 3], hi: [F; 3], t_min: F, t_max: F) -> Option<(F, F)> {
    let (mut t0, mut t1) = (t_min, t_max);
    for k in 0..3 {
        if inv_d[k].abs() == F::infinity() {
            if !(o[k] >= lo[k] && o[k] <= hi[k]) {
                return None;
            }
            continue;
        }
        let a = (lo[k] - o[k]) * inv_d[k];
        let b = (hi[k] - o[k]) * inv_d[k];
        // Explicit comparisons so a NaN never widens the interval.
        let (near, far) = if a <= b {
            (a, b)
        } else if b < a {
            (b, a)
        } else {
            return None;
        };
        if near > t0 {
            t0 = near;
        }
        if far < t1 {
            t1 = far;
        }
    }
    (t0 <= t1).then_some((t0, t1))
}

/// Componentwise 1/d. IEEE division already maps ±0 to ±∞ (sign from the
/// zero's sign bit), which `ray_box` treats as "parallel to that slab".
pub fn inv_dir<F: Real>(d: [F; 3]) -> [F; 3] {
    d.map(|x| F::one() / x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const INF: f64 = f64::INFINITY;
    const INF32: f32 = f32::INFINITY;

    // Triangle in the plane y = 0; the ray comes straight down from y = 2 and
    // hits (0.25, 0, 0.5) = 0.25·x0 + 0.25·x1 + 0.5·x2 at t = 2.
    const TRI: [[f64; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    const O: [f64; 3] = [0.25, 2.0, 0.5];
    const DOWN: [f64; 3] = [0.0, -1.0, 0.0];

    fn to32(a: [f64; 3]) -> [f32; 3] {
        a.map(|x| x as f32)
    }
    fn to64(a: [f32; 3]) -> [f64; 3] {
        a.map(|x| x as f64)
    }
    fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }
    fn norm(a: [f64; 3]) -> f64 {
        dot(a, a).sqrt()
    }
    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs()
    }
    fn wt(o: [f64; 3], d: [f64; 3], t_max: f32) -> Option<(f32, f32, f32, f32)> {
        watertight_f32(to32(o), to32(d), TRI.map(to32), t_max)
    }

    #[test]
    fn known_hit_all_variants() {
        let hit = FloatTri::new(TRI).unwrap().intersect(O, DOWN, 0.0, INF);
        assert_eq!(hit, Some((2.0, 0.5, 0.25)));
        let tri32 = FloatTri::new(TRI.map(to32)).unwrap();
        let hit = tri32.intersect(to32(O), to32(DOWN), 0.0, INF32);
        assert_eq!(hit, Some((2.0, 0.5, 0.25)));
        let (t, b0, b1, b2) = wt(O, DOWN, INF32).unwrap();
        for (got, want) in [(t, 2.0), (b0, 0.25), (b1, 0.25), (b2, 0.5)] {
            assert!((got - want).abs() < 1e-6, "{t} {b0} {b1} {b2}");
        }
        // (0.5, 0, 0) lies exactly on edge x0–x1: e2 is exactly 0 (the f64
        // fallback confirms it) and a hit on the edge counts.
        let (t, b0, b1, b2) = wt([0.5, 2.0, 0.0], DOWN, INF32).unwrap();
        assert_eq!((t, b2), (2.0, 0.0));
        assert!((b0 - 0.5).abs() < 1e-6 && (b1 - 0.5).abs() < 1e-6);
    }

    #[test]
    fn known_misses_and_degenerate() {
        let tri = FloatTri::new(TRI).unwrap();
        let outside = [2.0, 2.0, 2.0];
        let (up, side) = ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0]);
        assert_eq!(tri.intersect(outside, DOWN, 0.0, INF), None);
        assert_eq!(tri.intersect(O, DOWN, 0.0, 1.5), None, "t_max clips");
        assert_eq!(tri.intersect(O, DOWN, 2.5, INF), None, "t_min clips");
        assert_eq!(tri.intersect(O, up, 0.0, INF), None, "behind the origin");
        assert_eq!(tri.intersect(O, side, 0.0, INF), None, "parallel");
        assert_eq!(wt(outside, DOWN, INF32), None);
        assert_eq!(wt(O, DOWN, 1.5), None);
        assert_eq!(wt(O, up, INF32), None);
        assert_eq!(wt(O, side, INF32), None);
        // Degenerate triangles are refused up front.
        assert!(FloatTri::new([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0]]).is_none());
        assert!(FloatTri::new([[1.0f32; 3]; 3]).is_none());
    }

    #[test]
    fn ray_box_parallel_slabs() {
        let (lo, hi) = ([0.0f64; 3], [1.0f64; 3]);
        let inv = inv_dir([0.0f64, 1.0, 0.0]);
        assert!(inv[0].is_infinite() && inv[2].is_infinite());
        let hit = ray_box([0.5, -1.0, 0.5], inv, lo, hi, 0.0, INF);
        assert_eq!(hit, Some((1.0, 2.0)));
        assert_eq!(ray_box([1.5, -1.0, 0.5], inv, lo, hi, 0.0, INF), None);
        // Origin exactly on the x = 0 face with d.x = -0: naive 0·(−∞) = NaN.
        let inv = inv_dir([-0.0f32, 1.0, 0.0]);
        assert_eq!(inv[0], f32::NEG_INFINITY);
        let (lo, hi) = ([0.0f32; 3], [1.0f32; 3]);
        let hit = ray_box([0.0, -1.0, 0.5], inv, lo, hi, 0.0, INF32);
        assert_eq!(hit, Some((1.0, 2.0)));
        assert_eq!(ray_box([-1e-7, -1.0, 0.5], inv, lo, hi, 0.0, INF32), None);
        // Oblique ray, clipped by t_max and t_min.
        let inv = inv_dir([1.0f32; 3]);
        let o = [-1.0; 3];
        assert_eq!(ray_box(o, inv, lo, hi, 0.0, INF32), Some((1.0, 2.0)));
        assert_eq!(ray_box(o, inv, lo, hi, 0.0, 1.5), Some((1.0, 1.5)));
        assert_eq!(ray_box(o, inv, lo, hi, 2.5, INF32), None);
        let away = inv_dir([-1.0, 1.0, 1.0]);
        assert_eq!(ray_box(o, away, lo, hi, 0.0, INF32), None);
    }

    /// Near-exact (f64 from f32 inputs) ray parameter of the plane hit.
    fn plane_t(v: [[f32; 3]; 3], o: [f32; 3], w: [f32; 3]) -> f64 {
        let [x0, x1, x2] = v.map(to64);
        let n = cross(sub3(x1, x0), sub3(x2, x0));
        dot(n, sub3(x0, to64(o))) / dot(n, to64(w))
    }

    /// Well-shaped triangle and a ray that is not grazing: otherwise t itself
    /// is ill-conditioned and no fixed tolerance makes sense.
    fn well_conditioned(v: [[f32; 3]; 3], w: [f32; 3]) -> bool {
        let [x0, x1, x2] = v.map(to64);
        let n = cross(sub3(x1, x0), sub3(x2, x0));
        let l = [sub3(x1, x0), sub3(x2, x1), sub3(x0, x2)].map(norm);
        let lmax = l[0].max(l[1]).max(l[2]);
        let (nn, nw) = (norm(n), norm(to64(w)));
        lmax > 0.5 && nn > 0.05 * lmax * lmax && nw > 0.5 && dot(n, to64(w)).abs() > 0.1 * nn * nw
    }

    fn point(r: f32) -> impl Strategy<Value = [f32; 3]> {
        [-r..r, -r..r, -r..r]
    }

    /// Direction from o towards the point with barycentrics b (f64, rounded once).
    fn aim(v: [[f32; 3]; 3], b: [f64; 3], o: [f32; 3]) -> [f32; 3] {
        let x = v.map(to64);
        core::array::from_fn(|k| {
            let target = b[0] * x[0][k] + b[1] * x[1][k] + b[2] * x[2][k];
            (target - o[k] as f64) as f32
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            cases: 2000, max_global_rejects: 20000, ..ProptestConfig::default()
        })]

        #[test]
        fn interior_rays_hit_with_exact_t(
            v in [point(10.0), point(10.0), point(10.0)], o in point(20.0),
            s in 0.0f64..1.0, r in 0.0f64..1.0,
        ) {
            // b1, b2 and b0 = 1 − b1 − b2 all in [0.05, 0.9].
            let b1 = 0.05 + 0.85 * s;
            let b2 = 0.05 + (0.9 - b1) * r;
            let w = aim(v, [1.0 - b1 - b2, b1, b2], o);
            prop_assume!(well_conditioned(v, w));
            let t_ref = plane_t(v, o, w);

            let tri = FloatTri::new(v.map(to64)).unwrap();
            let (t, u, vv) = tri.intersect(to64(o), to64(w), 0.0, INF).unwrap();
            prop_assert!(close(t, t_ref, 1e-9), "f64 Wald t {} vs {}", t, t_ref);
            prop_assert!((u - b2).abs() < 1e-4 && (vv - b1).abs() < 1e-4);

            let (t, ..) = FloatTri::new(v).unwrap().intersect(o, w, 0.0, INF32).unwrap();
            prop_assert!(close(t as f64, t_ref, 1e-3), "f32 Wald t {} vs {}", t, t_ref);

            let (t, c0, c1, c2) = watertight_f32(o, w, v, INF32).unwrap();
            prop_assert!(close(t as f64, t_ref, 1e-4), "watertight t {} vs {}", t, t_ref);
            prop_assert!((c1 as f64 - b1).abs() < 1e-3 && (c2 as f64 - b2).abs() < 1e-3);
            prop_assert!((c0 + c1 + c2 - 1.0).abs() < 1e-5);

            // The same line pointing away, and a t_max short of the hit: misses.
            let back = w.map(|x| -x);
            prop_assert!(tri.intersect(to64(o), to64(back), 0.0, INF).is_none());
            prop_assert!(watertight_f32(o, back, v, INF32).is_none());
            prop_assert!(watertight_f32(o, w, v, (t_ref * 0.99) as f32).is_none());
            // Leaving from the (rounded) hit point, the self-intersection case: a
            // reported hit must truly lie ahead, which the t error bound ensures.
            let on: [f32; 3] = core::array::from_fn(|k| o[k] + w[k]);
            for dir in [w, back] {
                if let Some((t, ..)) = watertight_f32(on, dir, v, INF32) {
                    prop_assert!(plane_t(v, on, dir) > 0.0, "t = {} behind origin", t);
                }
            }
        }

        #[test]
        fn outside_rays_miss(
            v in [point(10.0), point(10.0), point(10.0)], o in point(20.0),
            neg in -1.0f64..-0.05, other in 0.0f64..1.0, k in 0usize..3,
        ) {
            // One barycentric clearly negative: the target is outside the triangle.
            let mut b = [neg, other, 1.0 - neg - other];
            b.rotate_right(k);
            let w = aim(v, b, o);
            prop_assume!(well_conditioned(v, w));
            let tri = FloatTri::new(v.map(to64)).unwrap();
            prop_assert!(tri.intersect(to64(o), to64(w), 0.0, INF).is_none());
            prop_assert!(FloatTri::new(v).unwrap().intersect(o, w, 0.0, INF32).is_none());
            prop_assert!(watertight_f32(o, w, v, INF32).is_none());
        }
    }

    /// Tiny deterministic generator (SplitMix64) for the many-trial loop below.
    struct Rng(u64);
    impl Rng {
        /// Uniform in [0, 1).
        fn next(&mut self) -> f32 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
        }
        fn vec(&mut self, scale: f32) -> [f32; 3] {
            [0; 3].map(|_| (2.0 * self.next() - 1.0) * scale)
        }
    }

    /// Two triangles (a, b, c) and (b, a, d) share edge a–b, with d roughly
    /// mirrored from c (slightly folded). A ray aimed at a point on a–b (rounded
    /// to f32) must hit at least one of them: never a crack.
    #[test]
    fn watertight_never_misses_shared_edge() {
        let mut rng = Rng(0x5eed);
        let (mut trials, mut cracks, mut wald_cracks) = (0, 0, 0);
        while trials < 200_000 {
            // Sizes from 0.01 to 100, placed up to 100 sizes away from the
            // world origin so that rounding in the transforms matters.
            let scale = 10f32.powf(4.0 * rng.next() - 2.0);
            let center = rng.vec(100.0 * scale);
            let [a, b, c] = [0; 3].map(|_| {
                let p = rng.vec(scale);
                [p[0] + center[0], p[1] + center[1], p[2] + center[2]]
            });
            let bump = rng.vec(0.1 * scale);
            let d: [f32; 3] = core::array::from_fn(|k| a[k] + b[k] - c[k] + bump[k]);
            let [a64, b64, c64] = [a, b, c].map(to64);
            let ab = sub3(b64, a64);
            let n = cross(ab, sub3(c64, a64));
            // c (hence d) must be well away from the line ab relative to the fold.
            let min_len = 0.3 * scale as f64;
            if norm(ab) < min_len || norm(n) < min_len * norm(ab) {
                continue;
            }
            trials += 1;
            let s = 0.1 + 0.8 * rng.next();
            let target: [f32; 3] = core::array::from_fn(|k| a[k] + s * (b[k] - a[k]));
            // Origin steeply above or below the surface, so the fold cannot
            // put both triangles on the same side of the edge as seen by the ray.
            let side = if rng.next() < 0.5 { -1.0 } else { 1.0 };
            let nn = n.map(|x| (side * x / norm(n)) as f32);
            let jitter = rng.vec(0.5);
            let dist = scale * (1.0 + 9.0 * rng.next());
            let o: [f32; 3] = core::array::from_fn(|k| target[k] + dist * (nn[k] + jitter[k]));
            let w = sub3(target, o);
            // Random vertex rotation of each triangle and orientation of the second.
            let (mut t1, mut t2) = ([a, b, c], [b, a, d]);
            t1.rotate_left((rng.next() * 3.0) as usize % 3);
            t2.rotate_left((rng.next() * 3.0) as usize % 3);
            if rng.next() < 0.5 {
                t2.swap(0, 1);
            }
            let hit = |t| watertight_f32(o, w, t, INF32).is_some();
            if !hit(t1) && !hit(t2) {
                cracks += 1;
            }
            let wald = |t| FloatTri::new(t).and_then(|f| f.intersect(o, w, 0.0, INF32)).is_some();
            if !wald(t1) && !wald(t2) {
                wald_cracks += 1;
            }
        }
        eprintln!("{trials} shared-edge rays: watertight cracks {cracks}, f32 Wald {wald_cracks}");
        assert_eq!(cracks, 0);
    }
}
