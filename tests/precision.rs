//! Acceptance: the golden model against the f64 reference, the epsilon rule for secondary
//! rays, and the software early out against the hardware-order traversal.

mod common;

use fxrt::model::camera::Camera;
use fxrt::model::ray::{dot, quantize_ray};
use fxrt::params::Params;
use fxrt::render::fast::FastGolden;
use fxrt::render::tracer::{GoldenTracer, ModelKind, make_tracer};
use fxrt::render::{compare, render};

#[test]
fn golden_agrees_with_f64_on_hit_or_miss_for_all_but_1_in_10000_rays() {
    let params = Params::default();
    for scene in common::all_scenes(&params) {
        let cam = Camera::default_for(&scene, 256, 256);
        let g = render(&scene, make_tracer(&scene, ModelKind::Golden).as_ref(), &cam, false, false);
        let f = render(&scene, make_tracer(&scene, ModelKind::F64).as_ref(), &cam, false, false);
        let d = compare::compare(&g, &f);
        eprintln!("{}: {} hits, {:?}, rate {:.2e}", scene.name, g.hits, d, d.rate());
        assert!(g.hits > 1000, "{}: the camera should see the scene", scene.name);
        assert!(d.rate() <= 1e-4, "{}: golden and f64 disagree on {} of {} rays", scene.name, d.hit_miss(), d.rays);
    }
}

#[test]
fn secondary_rays_never_hit_their_own_triangle() {
    let params = Params::default();
    for scene in common::all_scenes(&params) {
        let tracer = GoldenTracer::new(&scene);
        let g = &tracer.fast.golden;
        let cam = Camera::default_for(&scene, 128, 128);
        let (mut spawned, mut self_hits) = (0u64, 0u64);
        for py in 0..cam.height {
            for px in 0..cam.width {
                let ray = cam.ray(px, py);
                let Some(q) = quantize_ray(&scene, g, &ray) else { continue };
                let Some(hit) = g.trace(&scene, &q.ray).0 else { continue };
                let w = scene.world[scene.tri_ids[hit.tri as usize] as usize];
                let n = fxrt::model::ray::normalize(fxrt::model::ray::cross(
                    fxrt::model::ray::sub(w[1], w[0]),
                    fxrt::model::ray::sub(w[2], w[0]),
                ));
                let k = 2.0 * dot(ray.d, n);
                let reflected: [f64; 3] = std::array::from_fn(|i| ray.d[i] - k * n[i]);
                for dir in [reflected, ray.d] {
                    let s = tracer.secondary(&q.ray, &hit, dir);
                    spawned += 1;
                    if g.trace(&scene, &s).0.is_some_and(|h2| h2.tri == hit.tri) {
                        self_hits += 1;
                    }
                }
            }
        }
        eprintln!("{}: {spawned} secondary rays, {self_hits} self-intersections", scene.name);
        assert!(spawned > 1000);
        assert_eq!(self_hits, 0, "{}", scene.name);
    }
}

#[test]
fn early_out_gives_the_hardware_traversal_answer_bit_for_bit() {
    for params in [
        Params::default(),
        Params { n: 16, m: 16, ..Params::default() },
        Params { n: 23, m: 27, t: 5, ..Params::default() },
    ] {
        for scene in common::all_scenes(&params).into_iter().take(5) {
            let fast = FastGolden::new(&scene);
            let g = &fast.golden;
            let cam = Camera::default_for(&scene, 96, 96);
            let mut hits = 0;
            for py in 0..cam.height {
                for px in 0..cam.width {
                    let Some(q) = quantize_ray(&scene, g, &cam.ray(px, py)) else { continue };
                    let (full, fs) = g.trace(&scene, &q.ray);
                    let (quick, es) = fast.trace(&q.ray);
                    assert_eq!(full, quick, "{} pixel {px},{py}", scene.name);
                    assert!(es.tri_tests <= fs.tri_tests);
                    hits += full.is_some() as u32;
                }
            }
            assert!(hits > 100, "{}", scene.name);
        }
    }
}
