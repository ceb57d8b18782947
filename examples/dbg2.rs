use fxrt::params::Params;
use fxrt::render::camera::Camera;
use fxrt::render::tracer::{ModelKind, make_tracer};
use fxrt::scene::{Scene, SceneSource};
fn main() {
    let p = std::path::PathBuf::from(std::env::args().nth(1).unwrap());
    let s = Scene::load(&SceneSource::Obj(p), &Params::default()).unwrap();
    let cam = Camera::framing(&s, 256, 256);
    let f = make_tracer(&s, ModelKind::F64);
    let gt = make_tracer(&s, ModelKind::Golden);
    let mut shown = 0;
    for py in 0..256 {
        for px in 0..256 {
            let r = cam.ray(px, py);
            if let (Some(a), Some(b)) = (gt.primary(&r), f.primary(&r)) {
                if a.id != b.id && shown < 5 {
                    shown += 1;
                    println!(
                        "px {px},{py}: golden {} {:.6} f64 {} {:.6}; tri g {:?} f {:?}",
                        a.id, a.dist, b.id, b.dist, s.world[a.id as usize], s.world[b.id as usize]
                    );
                }
            }
        }
    }
}
