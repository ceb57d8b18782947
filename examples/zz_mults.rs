use fxrt::cores::core_params::{CoreParams, CoreSpec};
use fxrt::cores::top::core_module_with;
use fxrt::params::Params;
use fxrt::rtl::Module;
use fxrt::scene::images::SceneRoms;
use fxrt::scene::{Scene, SceneSource};
fn walk(m: &Module, depth: usize) {
    let b = fxrt::fpga::ecp5::blocks::blocks(m);
    if b.mult18 > 0 || b.dp16kd > 0 {
        println!("{}{} mult18 {} dp16kd {}", "  ".repeat(depth), m.name, b.mult18, b.dp16kd);
    }
    if depth < 3 {
        let mut seen = std::collections::BTreeSet::new();
        for i in &m.instances {
            if seen.insert(i.module.name.clone()) {
                walk(&i.module, depth + 1);
            }
        }
    }
}
fn main() {
    let params = Params { stack_depth: 16, ..Params::default() };
    let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &params).unwrap();
    let roms = SceneRoms::of(&scene);
    let p = CoreParams::shaped(&roms, &CoreSpec { units: 4, slots: 64, pipelines: 2, ..CoreSpec::default() });
    let m = core_module_with(&p, &roms, false);
    walk(&m, 0);
}
