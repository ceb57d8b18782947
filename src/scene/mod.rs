//! Scene pipeline: world triangles → n-bit integer grid → accelerated triangles → BIH.

pub mod accel;
pub mod bih;
pub mod builtin;
mod image_check;
pub mod images;
pub mod memory;
pub mod memory_c;
pub mod obj;
mod obj_lines;
pub mod report;
pub mod rom;

use crate::error::{Error, Result};
use crate::params::{EdgeShift, Params};
use accel::{AccelTri, GridVertex};
use bih::{Bih, BihStats, IBox};
use serde::Serialize;

/// A triangle as three world-space vertices.
pub type Tri = [[f64; 3]; 3];

/// Grid units left free around the scene on every side (see `Scene::build`).
pub const GUARD: i64 = 4;

/// World → grid: g = round((x − min) · scale); the scene's longest side spans
/// 2^n − 1 − 2·GUARD units, starting at GUARD.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GridTransform {
    pub min: [f64; 3],
    pub scale: f64,
}

impl GridTransform {
    pub fn to_grid_f64(&self, x: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|k| (x[k] - self.min[k]) * self.scale)
    }
    pub fn to_world(&self, g: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|k| g[k] / self.scale + self.min[k])
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct TriangleCounts {
    pub input: usize,
    pub degenerate: usize,
    pub clamped: usize,
    pub stored: usize,
}

/// Everything the golden model, the float references and the ROM writers need.
#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub params: Params,
    /// The edge shift actually used (resolved from `auto`).
    pub edge_shift: u32,
    pub transform: GridTransform,
    /// The box rays are clipped to: lo = 0, hi = the largest vertex coordinate + GUARD.
    pub grid_box: IBox,
    /// The triangle table, in input order with degenerate triangles removed.
    pub tris: Vec<AccelTri>,
    /// Input (file-order) number of each entry of `tris`.
    pub tri_ids: Vec<u32>,
    /// Grid vertices of each entry of `tris`.
    pub grid_tris: Vec<[GridVertex; 3]>,
    /// The input triangles in world space, in file order.
    pub world: Vec<Tri>,
    pub bih: Bih,
    pub bih_stats: BihStats,
    pub counts: TriangleCounts,
}

impl Scene {
    /// Runs the whole pipeline on world-space triangles. `source` names the scene in errors.
    pub fn build(name: &str, world: Vec<Tri>, params: &Params) -> Result<Scene> {
        params.validate()?;
        if world.is_empty() {
            return Err(Error::new(name, "no triangles"));
        }
        let (lo, extent) = world_extent(name, &world)?;
        // The scene spans [G, 2^n − 1 − G] on its longest axis: a ray clipped to the grid box
        // then starts at least G units before any surface, so the divider's t ≥ 1 cannot
        // reject a surface lying on the scene's bounding box (a Cornell box seen from outside).
        let top = ((1u64 << params.n) - 1) as f64;
        let guard = GUARD as f64;
        let scale = (top - 2.0 * guard) / extent;
        let transform = GridTransform { min: std::array::from_fn(|k| lo[k] - guard / scale), scale };
        let quantize_vertex = |v: [f64; 3]| -> GridVertex {
            transform.to_grid_f64(v).map(|g| g.round().clamp(guard, top - guard) as i64)
        };
        let grid_all: Vec<[GridVertex; 3]> = world.iter().map(|t| t.map(quantize_vertex)).collect();

        let edge_shift = match params.edge_shift {
            EdgeShift::Fixed(e) => e,
            EdgeShift::Auto => auto_edge_shift(&grid_all, params),
        };
        let mut counts = TriangleCounts { input: world.len(), ..Default::default() };
        let (mut tris, mut tri_ids, mut grid_tris) = (Vec::new(), Vec::new(), Vec::new());
        for (i, g) in grid_all.iter().enumerate() {
            match accel::quantize(g, params.f(), edge_shift) {
                None => counts.degenerate += 1,
                Some(q) => {
                    counts.clamped += q.clamped as usize;
                    tris.push(q.tri);
                    tri_ids.push(i as u32);
                    grid_tris.push(*g);
                }
            }
        }
        counts.stored = tris.len();
        if tris.is_empty() {
            return Err(Error::new(
                name,
                format!("all {} triangles are degenerate on the {}-bit grid", world.len(), params.n),
            ));
        }
        let grid_box = IBox::of_points(&grid_tris.iter().flatten().copied().collect::<Vec<_>>());
        let grid_box = IBox { lo: [0; 3], hi: grid_box.hi.map(|h| h + GUARD) };
        let bounds: Vec<IBox> = grid_tris.iter().map(|t| IBox::of_points(t)).collect();
        let (bih, bih_stats) = bih::build(
            &bounds,
            grid_box,
            params.leaf_size as usize,
            params.stack_depth as usize,
            params.tree,
            params.sah_step_percent,
        );
        Ok(Scene {
            name: name.to_string(),
            params: *params,
            edge_shift,
            transform,
            grid_box,
            tris,
            tri_ids,
            grid_tris,
            world,
            bih,
            bih_stats,
            counts,
        })
    }

    /// Loads an OBJ file or a built-in scene by name.
    pub fn load(source: &SceneSource, params: &Params) -> Result<Scene> {
        match source {
            SceneSource::Obj(path) => {
                let tris = obj::load_obj(path)?;
                Scene::build(&path.display().to_string(), tris, params)
            }
            SceneSource::Builtin(name) => {
                let tris = builtin::load(name)?;
                Scene::build(name, tris, params)
            }
        }
    }

    /// The edge components as real numbers, |x_ik − x_0k| / |n_r| (seed 001 figure 2.1).
    pub fn edge_components(&self) -> Vec<f64> {
        let mut out = Vec::with_capacity(4 * self.grid_tris.len());
        for g in &self.grid_tris {
            let n = accel::cross(g);
            let (r, p, q) = accel::axes(&n);
            for i in 1..3 {
                for k in [p, q] {
                    out.push(((g[i][k] - g[0][k]) as f64 / n[r] as f64).abs());
                }
            }
        }
        out
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SceneSource {
    Obj(std::path::PathBuf),
    Builtin(String),
}

/// The largest magnitude of a world coordinate, 2^200 (≈ 1.6e60), and the smallest extent of
/// a scene, 2^−200 (≈ 6.2e−61). Within them every world length L of the scene lies in
/// [2^−200, 2^202) and L^4 in the normal f64 range (2^−1022, 2^1023): squared lengths (the
/// default camera's radius) and the squared cross products that normalise a triangle's normal
/// stay finite and non-zero, and the grid scale (2^n − 9)/extent is finite. Beyond them the
/// scene built "fine" and failed later under another name (--eye, --at) or wrote a null scale.
pub const MAX_COORDINATE: f64 = 1.6069380442589903e60;
pub const MIN_EXTENT: f64 = 6.223015277861142e-61;

/// The bounding box (lo, hi) of world-space triangles.
pub fn world_box(tris: &[Tri]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in tris.iter().flatten() {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    (lo, hi)
}

/// The scene's lower corner and extent (its bounding box's longest side), checked against the
/// limits above; errors name the scene and the real cause.
fn world_extent(name: &str, world: &[Tri]) -> Result<([f64; 3], f64)> {
    for (i, t) in world.iter().enumerate() {
        if let Some(x) = t.iter().flatten().find(|x| !x.is_finite()) {
            return Err(Error::new(name, format!("triangle {i} has a non-finite coordinate ({x})")));
        }
        if let Some(x) = t.iter().flatten().find(|x| x.abs() > MAX_COORDINATE) {
            return Err(Error::new(
                name,
                format!(
                    "coordinates too large: triangle {i} has {x:e}; the scene's coordinates must lie within \
                     ±2^200 (±{MAX_COORDINATE:.2e}) so that its extent and the squares of its lengths stay finite"
                ),
            ));
        }
    }
    let (lo, hi) = world_box(world);
    let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    if extent == 0.0 {
        return Err(Error::new(name, "the scene has no extent: all vertices are at one point"));
    }
    if extent < MIN_EXTENT {
        return Err(Error::new(
            name,
            format!(
                "the scene's extent {extent:e} is too small to scale onto the grid: it must be at least 2^-200 \
                 ({MIN_EXTENT:.2e}), so that the squares of its lengths do not vanish"
            ),
        ));
    }
    Ok((lo, extent))
}

/// Upper bound on E so that edge quantisation (|Δx| · 2^(E+F), |Δx| < 2^n) fits the model.
pub fn max_edge_shift(params: &Params) -> u32 {
    params.max_edge_shift()
}

/// Seed 003's scene-adaptive edge shift: the largest E with every |e_ik| ≤ 2^−E, limited
/// to [0, max_edge_shift]. Triangles with |e_ik| > 1 cannot be helped by any E ≥ 0 and are
/// clamped (and counted) instead of costing every other triangle its precision.
pub fn auto_edge_shift(grid: &[[GridVertex; 3]], params: &Params) -> u32 {
    // The largest ratio a/b over all triangles, compared exactly by cross-multiplication.
    let (mut a, mut b) = (0i128, 1i128);
    for g in grid {
        if let Some((x, y)) = accel::max_edge_ratio(g)
            && x * b > a * y
        {
            (a, b) = (x, y);
        }
    }
    let cap = max_edge_shift(params);
    if a == 0 {
        return cap;
    }
    let mut e = 0;
    while e < cap && (a << (e + 1)) <= b {
        e += 1;
    }
    e
}

/// Relative-frequency histogram of edge components in seed 001 figure 2.1's bins:
/// [0, 0.0001), [0.0001, 0.0002), …, [0.0008, 0.0009), and ≥ 0.0009.
pub fn edge_histogram(components: &[f64]) -> [usize; 10] {
    let mut bins = [0usize; 10];
    for &c in components {
        let i = ((c / 0.0001).floor() as usize).min(9);
        bins[i] += 1;
    }
    bins
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri_scene() -> Vec<Tri> {
        vec![[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], [[0., 0., 1.], [1., 0., 1.], [0., 1., 1.]]]
    }

    #[test]
    fn grid_maps_longest_side_to_full_range() {
        let s = Scene::build("t", tri_scene(), &Params::default()).unwrap();
        assert_eq!(s.grid_box.hi, [(1 << 29) - 1; 3]);
        assert_eq!(s.grid_tris[0][0], [GUARD; 3]);
        assert_eq!(s.grid_tris[0][1], [(1 << 29) - 1 - GUARD, GUARD, GUARD]);
        assert_eq!(s.counts, TriangleCounts { input: 2, degenerate: 0, clamped: 0, stored: 2 });
    }

    #[test]
    fn degenerate_triangles_are_removed_and_counted() {
        let mut t = tri_scene();
        t.insert(1, [[0.5, 0.5, 0.5], [0.5, 0.5, 0.5], [0.2, 0.1, 0.0]]);
        let s = Scene::build("t", t, &Params::default()).unwrap();
        assert_eq!(s.counts.degenerate, 1);
        assert_eq!(s.tri_ids, vec![0, 2]);
    }

    #[test]
    fn bad_scenes_are_errors() {
        let p = Params::default();
        assert!(Scene::build("x", vec![], &p).unwrap_err().message.contains("no triangles"));
        let point = vec![[[1.0, 1.0, 1.0]; 3]];
        assert!(Scene::build("x", point, &p).unwrap_err().message.contains("no extent"));
        let flat = vec![[[0., 0., 0.], [1., 1., 1.], [2., 2., 2.]]];
        assert!(Scene::build("x", flat, &p).unwrap_err().message.contains("degenerate"));
        let nan = vec![[[0., 0., f64::NAN], [1., 0., 0.], [0., 1., 0.]]];
        assert!(Scene::build("x", nan, &p).unwrap_err().message.contains("non-finite"));
    }

    /// Coordinates of ±1e300 built (and failed later as "--eye"), ±1.7e308 overflowed the
    /// extent into "no extent", a denormal extent wrote a null scale: each now names its cause.
    #[test]
    fn extents_beyond_the_limits_name_their_cause() {
        let p = Params::default();
        let tri = |a: f64, b: f64| vec![[[a, 0., 0.], [b, 0., 0.], [0., b, 0.]]];
        for (t, want) in [
            (tri(-1e300, 1e300), "coordinates too large: triangle 0 has -1e300"),
            (tri(-1.7e308, 1.7e308), "coordinates too large"),
            (tri(0.0, 1e-310), "extent 1e-310 is too small to scale onto the grid"),
            (tri(0.0, MIN_EXTENT / 2.0), "too small to scale"),
        ] {
            let e = Scene::build("s.obj", t, &p).unwrap_err().to_string();
            assert!(e.starts_with("s.obj: ") && e.contains(want), "{e:?} should contain {want:?}");
        }
        assert_eq!((MAX_COORDINATE, MIN_EXTENT), (2f64.powi(200), 2f64.powi(-200)));
        // At the limits the scene builds with a finite, positive scale.
        for t in [tri(-MAX_COORDINATE, MAX_COORDINATE), tri(0.0, MIN_EXTENT)] {
            let s = Scene::build("s", t, &p).unwrap();
            assert!(
                s.transform.scale.is_finite()
                    && s.transform.scale > 0.0
                    && s.transform.min.iter().all(|x| x.is_finite())
            );
        }
    }

    #[test]
    fn auto_edge_shift_fits_the_largest_edge() {
        let s = Scene::build("t", tri_scene(), &Params::default()).unwrap();
        // Right triangle with legs L: n_r = L², e = L / L² = 1/L, L = 2^29 − 9 → E = 28.
        assert_eq!(s.edge_shift, 28);
        assert_eq!(s.counts.clamped, 0);
        let max = s.edge_components().into_iter().fold(0.0, f64::max);
        assert!(max <= 2f64.powi(-(s.edge_shift as i32)) && max > 2f64.powi(-(s.edge_shift as i32) - 1));
    }
}
