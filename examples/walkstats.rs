//! Traversal figures of the BIH, middle split against SAH (DECISIONS.md 72): for every
//! built-in scene (Cornell at n = m = 20, the others at the default parameters), the primary
//! rays of a W×H frame from the default camera, traced with `Golden::trace_culled` (the
//! hardware's early-out walk): node steps per ray (visits + culled entries), leaf visits per
//! ray and those of them entered straight from the parent's step (the steps a parent that sends
//! its leaf child to the leaf stream would save; docs/CORE.md, the ceiling), triangle tests
//! per ray, and the tree's size (nodes, leaf entries: the ROM depths). Every ray's hit is also
//! checked against `Golden::trace` (the full walk); they must agree.
//!
//! cargo run --release --example walkstats -- [--leaf 1,2,4,8] [--split middle,sah]
//!     [--scenes teapot,cornell] [--size 128]

use fxrt::model::camera::Camera;
use fxrt::model::golden::Golden;
use fxrt::model::ray::quantize_ray;
use fxrt::params::{Params, TreeSplit};
use fxrt::scene::{Scene, SceneSource};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let opt = |name: &str| args.iter().position(|a| a == name).map(|i| args[i + 1].clone());
    let list = |s: String| s.split(',').map(str::to_string).collect::<Vec<_>>();
    let leaves: Vec<u32> = opt("--leaf")
        .map(list)
        .unwrap_or(vec!["1".into(), "2".into(), "4".into(), "8".into()])
        .iter()
        .map(|s| s.parse().unwrap())
        .collect();
    let splits: Vec<TreeSplit> = opt("--split")
        .map(list)
        .map(|l| l.iter().map(|s| s.parse().unwrap()).collect())
        .unwrap_or(TreeSplit::ALL.to_vec());
    let scenes = opt("--scenes")
        .map(list)
        .unwrap_or(fxrt::scene::builtin::BUILTIN_NAMES.iter().map(|s| s.to_string()).collect());
    let size: u32 = opt("--size").map(|s| s.parse().unwrap()).unwrap_or(128);
    println!(
        "| scene | leaf | split | node steps/ray | of which culled | leaf visits/ray | of which from the parent | tri tests/ray | nodes | leaf entries | depth | max leaf | build s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for name in &scenes {
        for &leaf in &leaves {
            for &tree in &splits {
                let mut params = Params { leaf_size: leaf, tree, ..Params::default() };
                if name == "cornell" {
                    params.n = 20;
                    params.m = 20;
                }
                let t0 = std::time::Instant::now();
                let scene = Scene::load(&SceneSource::Builtin(name.clone()), &params).unwrap();
                let build = t0.elapsed().as_secs_f64();
                let g = Golden::new(&scene);
                let cam = Camera::default_for(&scene, size, size);
                let (mut rays, mut steps, mut culls, mut tests) = (0u64, 0u64, 0u64, 0u64);
                let (mut leaves, mut from_parent) = (0u64, 0u64);
                for py in 0..size {
                    for px in 0..size {
                        let Some(q) = quantize_ray(&scene, &g, &cam.ray(px, py)) else { continue };
                        let (full, _) = g.trace(&scene, &q.ray);
                        let (hit, s) = g.trace_culled(&scene, &q.ray);
                        assert_eq!(full, hit, "{name} leaf {leaf} {tree}: pixel ({px}, {py})");
                        rays += 1;
                        steps += (s.nodes + s.culled) as u64;
                        culls += s.culled as u64;
                        tests += s.tri_tests as u64;
                        leaves += s.leaves as u64;
                        from_parent += s.leaves_from_parent as u64;
                    }
                }
                let per = |x: u64| x as f64 / rays as f64;
                let b = &scene.bih_stats;
                println!(
                    "| {name} | {leaf} | {tree} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {} | {} | {} | {} | {build:.2} |",
                    per(steps),
                    per(culls),
                    per(leaves),
                    per(from_parent),
                    per(tests),
                    b.nodes,
                    scene.bih.leaf_tris.len(),
                    b.depth,
                    b.max_leaf_size,
                );
            }
        }
    }
}
