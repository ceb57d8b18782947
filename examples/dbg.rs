use fxrt::model::golden::Golden;
use fxrt::model::ray::quantize_ray;
use fxrt::params::Params;
use fxrt::render::camera::Camera;
use fxrt::render::tracer::{ModelKind, make_tracer};
use fxrt::scene::{Scene, SceneSource};
fn main() {
    let name = std::env::args().nth(1).unwrap();
    let s = Scene::load(&SceneSource::Builtin(name), &Params::default()).unwrap();
    let cam = Camera::framing(&s, 256, 256);
    let g = Golden::new(&s);
    let f = make_tracer(&s, ModelKind::F64);
    let gt = make_tracer(&s, ModelKind::Golden);
    let mut shown = 0;
    for py in 0..256 {
        for px in 0..256 {
            let r = cam.ray(px, py);
            let a = gt.primary(&r);
            let b = f.primary(&r);
            if a.is_none() && b.is_some() && shown < 3 {
                shown += 1;
                let q = quantize_ray(&s, &g, &r).unwrap();
                let brute: Vec<_> =
                    (0..s.tris.len()).filter_map(|i| g.intersect(&s.tris[i], &q.ray).map(|h| (h.t, i))).collect();
                let mut visited = vec![];
                g.traverse(&s, &q.ray, |i, _| visited.push(i));
                let fid = b.unwrap().id;
                let ti = s.tri_ids.iter().position(|&x| x == fid).unwrap();
                println!(
                    "px {px},{py} ray o={:?} w={:?} f64 hit id {} dist {}; brute golden {:?}; visited {:?}; tri {:?}; box_exit {}",
                    q.ray.o,
                    q.ray.w,
                    fid,
                    b.unwrap().dist,
                    brute,
                    visited.len(),
                    s.tris[ti],
                    g.box_exit(&q.ray)
                );
            }
        }
    }
}
