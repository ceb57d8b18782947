use fxrt::model::golden::Golden;
use fxrt::model::ray::quantize_ray;
use fxrt::params::Params;
use fxrt::render::camera::Camera;
use fxrt::scene::{Scene, SceneSource};
fn main() {
    let s = Scene::load(&SceneSource::Builtin("teapot".into()), &Params::default()).unwrap();
    let cam = Camera::framing(&s, 256, 256);
    let g = Golden::new(&s);
    let (mut n, mut t, mut rays, mut ms) = (0u64, 0u64, 0u64, 0u32);
    for py in 0..256 {
        for px in 0..256 {
            if let Some(q) = quantize_ray(&s, &g, &cam.ray(px, py)) {
                let (_, st) = g.trace_fast(&s, &q.ray);
                n += st.nodes as u64;
                t += st.tri_tests as u64;
                rays += 1;
                ms = ms.max(st.max_stack);
            }
        }
    }
    println!(
        "rays in box {rays}, nodes/ray {:.1}, tri tests/ray {:.1}, max stack {ms}, bih {:?}",
        n as f64 / rays as f64,
        t as f64 / rays as f64,
        s.bih_stats
    );
}
