//! Cache study for the scene in external memory (issue 29, docs/MEMORY.md "Why these caches"):
//! the node and triangle reads of every primary ray of a W×H frame (the hardware's early-out
//! walk, `Golden::trace_culled`), `--slots` rays interleaved one access at a time (the slot
//! core's round robin, roughly), fed in pixel order or in tiles, through two set-associative
//! LRU caches. Prints hit rates and bytes read from memory per ray for every cache size.
//! A trace model, not the hardware: the cycle simulator's figures (`fxrt sim`) are the ones
//! that count; this one chose the line sizes and the default cache sizes.
//!
//! cargo run --release --example memory_study -- [--scene teapot-fine] [--size 512]
//!     [--slots 32] [--line 64,128,256] [--ways 2] [--kb 8,16,32,64,128,256] [--tiles 0,8]

use fxrt::model::camera::Camera;
use fxrt::model::golden::{Closest, Culled, Golden, Visitor};
use fxrt::model::ray::quantize_ray;
use fxrt::params::Params;
use fxrt::scene::{Scene, SceneSource};

#[derive(Clone, Copy)]
enum Access {
    Node(u32),
    Tri(u32),
}

struct Recorder<'a> {
    walk: Culled<'a>,
    pos: &'a [u32],
    trace: Vec<Access>,
}

impl Visitor for Recorder<'_> {
    fn triangle(&mut self, tri: u32, leaf_tmin: i64) {
        self.trace.push(Access::Tri(self.pos[tri as usize]));
        self.walk.triangle(tri, leaf_tmin)
    }
    fn prune(&self, tmin: i64) -> bool {
        self.walk.prune(tmin)
    }
    fn node(&mut self, node: u32) {
        self.trace.push(Access::Node(node));
    }
}

/// A set-associative cache with LRU replacement over line numbers.
struct Cache {
    sets: usize,
    ways: usize,
    tags: Vec<(u64, u64)>, // (line, last use); line u64::MAX = empty
    clock: u64,
    hits: u64,
    misses: u64,
}

impl Cache {
    fn new(bytes: usize, line: usize, ways: usize) -> Cache {
        let sets = (bytes / line / ways).max(1);
        Cache { sets, ways, tags: vec![(u64::MAX, 0); sets * ways], clock: 0, hits: 0, misses: 0 }
    }
    fn access(&mut self, line: u64) -> bool {
        self.clock += 1;
        let set = (line as usize) % self.sets;
        let ways = &mut self.tags[set * self.ways..(set + 1) * self.ways];
        if let Some(w) = ways.iter_mut().find(|w| w.0 == line) {
            w.1 = self.clock;
            self.hits += 1;
            return true;
        }
        self.misses += 1;
        let victim = if std::env::var("RANDOM_VICTIM").is_ok_and(|v| v == "1") {
            // A round-robin counter over the misses: no per-set state.
            &mut ways[(self.misses as usize) % self.ways]
        } else {
            ways.iter_mut().min_by_key(|w| w.1).unwrap()
        };
        *victim = (line, self.clock);
        false
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let opt =
        |name: &str, d: &str| args.iter().position(|a| a == name).map(|i| args[i + 1].clone()).unwrap_or(d.into());
    let nums = |s: String| s.split(',').map(|x| x.parse::<usize>().unwrap()).collect::<Vec<_>>();
    let name = opt("--scene", "teapot-fine");
    let size: u32 = opt("--size", "256").parse().unwrap();
    let slots: usize = opt("--slots", "32").parse().unwrap();
    let ways: usize = opt("--ways", "2").parse().unwrap();
    let lines = nums(opt("--line", "64,128,256"));
    let kbs = nums(opt("--kb", "8,16,32,64,128,256"));
    let tiles = nums(opt("--tiles", "0,8"));
    let scene = Scene::load(&SceneSource::Builtin(name.clone()), &Params::default()).unwrap();
    let g = Golden::new(&scene);
    let mut pos = vec![u32::MAX; scene.tris.len()];
    for (i, &t) in scene.bih.leaf_tris.iter().enumerate() {
        assert_eq!(pos[t as usize], u32::MAX, "triangle {t} in two leaves");
        pos[t as usize] = i as u32;
    }
    let [tl, nl, _] = fxrt::scene::rom::layouts(&scene);
    println!(
        "{name} {size}²: {} nodes of {} bits, {} triangles of {} bits, {slots} rays interleaved, {ways} ways",
        scene.bih.nodes.len(),
        nl.width,
        scene.tris.len(),
        tl.width
    );
    let cam = Camera::default_for(&scene, size, size);
    for &tile in &tiles {
        let mut order: Vec<(u32, u32)> = Vec::new();
        if tile == 0 {
            order = (0..size).flat_map(|y| (0..size).map(move |x| (x, y))).collect();
        } else {
            let t = tile as u32;
            for ty in (0..size).step_by(tile) {
                for tx in (0..size).step_by(tile) {
                    for y in ty..(ty + t).min(size) {
                        for x in tx..(tx + t).min(size) {
                            order.push((x, y));
                        }
                    }
                }
            }
        }
        let traces: Vec<Vec<Access>> = order
            .iter()
            .filter_map(|&(x, y)| {
                let q = quantize_ray(&scene, &g, &cam.ray(x, y))?;
                let mut r = Recorder { walk: Culled(Closest::new(&g, &scene, &q.ray)), pos: &pos, trace: Vec::new() };
                g.walk(&scene, &q.ray, &mut r);
                Some(r.trace)
            })
            .collect();
        let rays = traces.len() as f64;
        let (nodes, tris) = traces.iter().flatten().fold((0u64, 0u64), |(n, t), a| match a {
            Access::Node(_) => (n + 1, t),
            Access::Tri(_) => (n, t + 1),
        });
        println!(
            "order {}: {} rays, {:.1} node reads, {:.1} triangle reads per ray",
            if tile == 0 { "pixels".to_string() } else { format!("tiles {tile}×{tile}") },
            rays,
            nodes as f64 / rays,
            tris as f64 / rays
        );
        println!("| line B | node KB | node hit | tri KB | tri hit | bytes/ray |");
        println!("|---|---|---|---|---|---|");
        for &line in &lines {
            // Nodes: 16-byte records, the root alone, each child pair in one 32-byte block.
            // Triangles: 40-byte records (five 64-bit beats), as many per line as fit.
            let (node_b, tri_b) = (16usize, 40usize);
            let tris_per_line = (line / tri_b).max(1) as u64;
            for &kb in &kbs {
                let mut nc = Cache::new(kb * 1024, line, ways);
                let mut tc = Cache::new(kb * 1024, line, ways);
                let mut bytes = 0u64;
                // Round robin over `slots` rays; a finished ray's slot takes the next ray.
                let mut live: Vec<(usize, usize)> = Vec::new();
                let mut next = 0usize;
                loop {
                    while live.len() < slots && next < traces.len() {
                        live.push((next, 0));
                        next += 1;
                    }
                    if live.is_empty() {
                        break;
                    }
                    live.retain_mut(|(r, k)| {
                        match traces[*r][*k] {
                            Access::Node(i) => {
                                let addr = (i as u64 + 1) * node_b as u64;
                                if !nc.access(addr / line as u64) {
                                    bytes += line as u64;
                                }
                            }
                            Access::Tri(i) => {
                                if !tc.access(i as u64 / tris_per_line) {
                                    bytes += line as u64;
                                }
                            }
                        }
                        *k += 1;
                        *k < traces[*r].len()
                    });
                }
                let rate = |c: &Cache| c.hits as f64 / (c.hits + c.misses).max(1) as f64;
                println!("| {line} | {kb} | {:.4} | {kb} | {:.4} | {:.1} |", rate(&nc), rate(&tc), bytes as f64 / rays);
            }
        }
    }
}
