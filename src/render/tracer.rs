//! One interface over the four models `--model` selects: primary hits and shadow rays.

use crate::model::float::Real;
use crate::model::golden::{Golden, GridRay, Hit};
use crate::model::ray::{WorldRay, dot, normalize, quantize_direction, quantize_ray, sub};
use crate::model::reference::{FloatScene, FloatTest};
use crate::scene::Scene;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ModelKind {
    /// The bit-exact integer model of the hardware.
    Golden,
    /// Hanika's triangle test and the same BIH in f64.
    F64,
    /// The same in f32.
    F32,
    /// pbrt's watertight triangle test in f32, same BIH.
    Watertight,
}

/// A primary hit: input triangle number and world-space distance from the ray origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimaryHit {
    pub id: u32,
    pub dist: f64,
    /// For the golden model: the grid ray and hit, needed to spawn secondary rays exactly.
    pub grid: Option<(GridRay, Hit)>,
}

pub trait Tracer: Sync {
    fn primary(&self, ray: &WorldRay) -> Option<PrimaryHit>;
    /// Whether something blocks the segment from the hit to the point light.
    fn shadowed(&self, ray: &WorldRay, hit: &PrimaryHit, light: [f64; 3]) -> bool;
}

pub struct GoldenTracer<'a> {
    pub scene: &'a Scene,
    pub golden: Golden,
}

impl<'a> GoldenTracer<'a> {
    pub fn new(scene: &'a Scene) -> Self {
        GoldenTracer { scene, golden: Golden::new(scene) }
    }

    /// A secondary ray from the hit of `ray` on table triangle `hit.tri`, leaving along the
    /// world direction `dir`, spawned with the 2-unit rule of seed 001 §2.1.5.
    pub fn secondary(&self, ray: &GridRay, hit: &Hit, dir: [f64; 3]) -> GridRay {
        let g = &self.golden;
        let w = quantize_direction(dir, g.f);
        let h = g.hit_point(ray, hit.t);
        let o = g.spawn_origin(&self.scene.tris[hit.tri as usize], h, w);
        g.ray(o, w)
    }
}

impl Tracer for GoldenTracer<'_> {
    fn primary(&self, ray: &WorldRay) -> Option<PrimaryHit> {
        let q = quantize_ray(self.scene, &self.golden, ray)?;
        let (hit, _) = self.golden.trace_fast(self.scene, &q.ray);
        let hit = hit?;
        Some(PrimaryHit {
            id: self.scene.tri_ids[hit.tri as usize],
            dist: (q.t_offset + hit.t as f64) / self.scene.transform.scale,
            grid: Some((q.ray, hit)),
        })
    }

    fn shadowed(&self, _ray: &WorldRay, hit: &PrimaryHit, light: [f64; 3]) -> bool {
        let Some((gray, ghit)) = hit.grid else { return false };
        let h = self.golden.hit_point(&gray, ghit.t).map(|x| x as f64);
        let to_light = sub(self.scene.transform.to_grid_f64(light), h);
        let dist = dot(to_light, to_light).sqrt();
        let sray = self.secondary(&gray, &ghit, normalize(to_light));
        match self.golden.trace_fast(self.scene, &sray).0 {
            Some(b) => (b.t as f64) < dist - 2.0,
            None => false,
        }
    }
}

pub struct FloatTracer<F: Real> {
    pub fs: FloatScene<F>,
    /// Offset of shadow-ray origins along the normal, in world units.
    pub eps: f64,
    normals: Vec<[f64; 3]>,
}

impl<F: Real> FloatTracer<F> {
    pub fn new(scene: &Scene, test: FloatTest) -> Self {
        let normals = scene.world.iter().map(|t| normalize(crate::model::ray::cross(sub(t[1], t[0]), sub(t[2], t[0])))).collect();
        FloatTracer { fs: FloatScene::new(scene, test), eps: 4.0 / scene.transform.scale, normals }
    }
}

impl<F: Real> Tracer for FloatTracer<F> {
    fn primary(&self, ray: &WorldRay) -> Option<PrimaryHit> {
        let (id, t) = self.fs.trace(ray.o.map(F::from_f64), ray.d.map(F::from_f64))?;
        Some(PrimaryHit { id, dist: t.to_f64(), grid: None })
    }

    fn shadowed(&self, ray: &WorldRay, hit: &PrimaryHit, light: [f64; 3]) -> bool {
        let p: [f64; 3] = std::array::from_fn(|k| ray.o[k] + hit.dist * ray.d[k]);
        let to_light = sub(light, p);
        let dist = dot(to_light, to_light).sqrt();
        let d = normalize(to_light);
        let n = self.normals[hit.id as usize];
        let side = if dot(n, d) >= 0.0 { 1.0 } else { -1.0 };
        let o: [f64; 3] = std::array::from_fn(|k| p[k] + side * self.eps * n[k]);
        match self.fs.trace(o.map(F::from_f64), d.map(F::from_f64)) {
            Some((_, t)) => t.to_f64() < dist - self.eps,
            None => false,
        }
    }
}

/// The tracer for `kind`, boxed so the renderer needs no generics.
pub fn make_tracer<'a>(scene: &'a Scene, kind: ModelKind) -> Box<dyn Tracer + 'a> {
    match kind {
        ModelKind::Golden => Box::new(GoldenTracer::new(scene)),
        ModelKind::F64 => Box::new(FloatTracer::<f64>::new(scene, FloatTest::Wald)),
        ModelKind::F32 => Box::new(FloatTracer::<f32>::new(scene, FloatTest::Wald)),
        ModelKind::Watertight => Box::new(FloatTracer::<f32>::new(scene, FloatTest::Watertight)),
    }
}
