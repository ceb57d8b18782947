//! The scene image for external memory as a host program meets it: `fxrt scene` writes
//! scene.bin and fxrt_scene.h; a C program walks the tree in the image with the header's
//! macros alone and must find, leaf by leaf, the triangles (numbers and fields) the golden
//! model's BIH holds. Bad shapes are refused before anything is written.

use fxrt::params::Params;
use fxrt::scene::bih::Node;
use fxrt::scene::{Scene, SceneSource};
use std::process::{Command, Output};

fn fxrt(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fxrt")).args(args).output().expect("fxrt runs")
}

const WALK: &str = r#"
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include "fxrt_scene.h"

static uint8_t *img;

static void walk(uint64_t k) {
    const uint8_t *n = img + fxrt_scene_node_address(k);
    uint64_t axis = fxrt_scene_field(n, FXRT_SCENE_NODE_AXIS_LSB, FXRT_SCENE_NODE_AXIS_WIDTH);
    if (axis == 3) {
        uint64_t p = fxrt_scene_field(n, FXRT_SCENE_NODE_FIRST_LSB, FXRT_SCENE_NODE_FIRST_WIDTH);
        uint64_t count = fxrt_scene_field(n, FXRT_SCENE_NODE_COUNT_LSB, FXRT_SCENE_NODE_COUNT_WIDTH);
        printf("leaf %" PRIu64 "\n", count);
        for (uint64_t i = 0; i < count; i++, p = fxrt_scene_next(p)) {
            const uint8_t *t = img + fxrt_scene_tri_address(p);
            printf("%" PRIu64 " %" PRId64 " %" PRId64 " %" PRIu64 "\n",
                   fxrt_scene_field(t, FXRT_SCENE_TRI_ID_LSB, FXRT_SCENE_TRI_ID_WIDTH),
                   fxrt_scene_sfield(t, FXRT_SCENE_TRI_E2Q_LSB, FXRT_SCENE_TRI_E2Q_WIDTH),
                   fxrt_scene_sfield(t, FXRT_SCENE_TRI_D_LSB, FXRT_SCENE_TRI_D_WIDTH),
                   fxrt_scene_field(t, FXRT_SCENE_TRI_PQ_LSB, FXRT_SCENE_TRI_PQ_WIDTH));
        }
    } else {
        printf("inner %" PRIu64 " %" PRIu64 "\n", axis,
               fxrt_scene_field(n, FXRT_SCENE_NODE_CLIP1_LSB, FXRT_SCENE_NODE_CLIP1_WIDTH));
        uint64_t child = fxrt_scene_field(n, FXRT_SCENE_NODE_CHILD_LSB, FXRT_SCENE_NODE_CHILD_WIDTH);
        walk(child);
        walk(child + 1);
    }
}

int main(int argc, char **argv) {
    FILE *f = fopen(argv[argc - 1], "rb");
    if (!f) return 1;
    img = malloc(FXRT_SCENE_TOTAL_BYTES);
    if (fread(img, 1, FXRT_SCENE_TOTAL_BYTES, f) != FXRT_SCENE_TOTAL_BYTES) return 2;
    walk(FXRT_SCENE_ROOT_RECORD);
    return 0;
}
"#;

/// The same walk over the golden model's BIH and triangle table.
fn expected(scene: &Scene, node: u32, out: &mut Vec<String>) {
    match scene.bih.nodes[node as usize] {
        Node::Leaf { first, count } => {
            out.push(format!("leaf {count}"));
            for &t in &scene.bih.leaf_tris[first as usize..(first + count) as usize] {
                let tri = &scene.tris[t as usize];
                out.push(format!("{t} {} {} {}", tri.e2q, tri.d, tri.pq));
            }
        }
        Node::Inner { axis, clip1, child, .. } => {
            out.push(format!("inner {axis} {clip1}"));
            expected(scene, child, out);
            expected(scene, child + 1, out);
        }
    }
}

#[test]
fn a_c_program_walks_the_image_with_the_header_alone() {
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    for (builtin, extra, params) in [
        ("teapot", vec![], Params::default()),
        (
            "random",
            vec!["--mem-bits", "128", "--cache-line", "256", "--n", "12", "--m", "14", "--leaf-size", "3"],
            Params { n: 12, m: 14, leaf_size: 3, ..Params::default() },
        ),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("s");
        let mut args = vec!["scene", "--builtin", builtin, "--out", out.to_str().unwrap()];
        args.extend(extra.iter().copied());
        let o = fxrt(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::write(out.join("walk.c"), WALK).unwrap();
        let exe = out.join("walk");
        let c = Command::new(&cc)
            .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O1", "-o"])
            .arg(&exe)
            .arg(out.join("walk.c"))
            .output()
            .unwrap();
        assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
        let run = Command::new(&exe).arg(out.join("scene.bin")).output().unwrap();
        assert!(run.status.success(), "walk exited {:?}", run.status);
        let scene = Scene::load(&SceneSource::Builtin(builtin.into()), &params).unwrap();
        let mut want = Vec::new();
        expected(&scene, 0, &mut want);
        let got = String::from_utf8(run.stdout).unwrap();
        assert_eq!(got.lines().collect::<Vec<_>>(), want, "{builtin}");
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("scene.json")).unwrap()).unwrap();
        let bytes = std::fs::metadata(out.join("scene.bin")).unwrap().len();
        assert_eq!(json["memory"]["total_bytes"], bytes, "scene.json's layout names the image's size");
    }
}

#[test]
fn shapes_the_port_cannot_take_are_refused_before_writing() {
    for (flag, value, named) in [
        ("--cache-line", "100", "--cache-line"),
        ("--cache-line", "8192", "--cache-line"),
        ("--mem-bits", "48", "--mem-bits"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("s");
        let o = fxrt(&["scene", "--builtin", "teapot", "--out", out.to_str().unwrap(), flag, value]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{flag} {value}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(named), "{err}");
        assert!(!out.exists(), "{flag} {value}: something was written");
    }
}
