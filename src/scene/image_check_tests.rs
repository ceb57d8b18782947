//! The image checks on real scenes' ROM images (`SceneRoms`, which runs them): a test file of
//! its own, as it needs `scene::images`, which needs `image_check`.

use super::super::images::SceneRoms;
use super::super::{Scene, report, rom};
use crate::params::{EdgeShift, Params};
use std::path::Path;

/// Field values set in a word: (field, value).
type Fields<'a> = &'a [(&'a str, i128)];

/// Six triangles apart from each other: with leaf size 1 a tree of depth 3.
fn scene(e: EdgeShift) -> Scene {
    let tris = (0..6)
        .map(|i| {
            let x = [(i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64].map(|c| 4.0 * c);
            [x, [x[0] + 1.0, x[1], x[2]], [x[0], x[1] + 1.0, x[2] + 1.0]]
        })
        .collect();
    Scene::build("eight", tris, &Params { n: 12, m: 16, edge_shift: e, leaf_size: 1, ..Params::default() }).unwrap()
}

/// The folder `fxrt scene` writes for `s` (scene.json and the .hex files).
fn folder(s: &Scene) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let roms = rom::words(s);
    for (l, w) in &roms {
        std::fs::write(dir.path().join(format!("{}.hex", l.rom)), rom::readmemh(l, w)).unwrap();
    }
    let json = serde_json::to_string_pretty(&report::scene_json(s, &roms)).unwrap();
    std::fs::write(dir.path().join("scene.json"), json).unwrap();
    dir
}

fn edit_json(dir: &Path, f: impl FnOnce(&mut serde_json::Value)) {
    let p = dir.join("scene.json");
    let mut j: serde_json::Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    f(&mut j);
    std::fs::write(p, serde_json::to_vec(&j).unwrap()).unwrap();
}

/// Sets field `name` of word `k` of ROM `rom` (0 tri, 1 node, 2 leaf) to `v`.
fn edit_word(dir: &Path, s: &Scene, rom: usize, k: usize, fields: &[(&str, i128)]) {
    let l = &rom::layouts(s)[rom];
    let p = dir.join(format!("{}.hex", l.rom));
    let text = std::fs::read_to_string(&p).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut w = rom::Word::from_hex(&lines[k + 1]).unwrap();
    for &(name, v) in fields {
        let f = l.field(name);
        w = rom::Word(w.0.iter().enumerate().map(|(i, &x)| x & !field_mask(f, i)).collect());
        w.set(f, v);
    }
    lines[k + 1] = w.hex(l.width);
    std::fs::write(p, lines.join("\n") + "\n").unwrap();
}

/// The bits of limb `i` that field `f` covers.
fn field_mask(f: &rom::Field, i: usize) -> u64 {
    (f.lsb..f.lsb + f.width).filter(|b| (b / 64) as usize == i).fold(0, |m, b| m | 1 << (b % 64))
}

/// Loading fails with one line starting `dir/<file>` and containing `want`.
fn refused(dir: &Path, file: &str, want: &str) {
    let e = SceneRoms::load(dir).unwrap_err().to_string();
    let at = dir.join(file).display().to_string();
    assert!(e.starts_with(&at) && e.contains(want), "{e:?} should name {at} and say {want:?}");
    assert!(!e.contains('\n'));
}

#[test]
fn a_written_folder_loads_as_built() {
    for e in [EdgeShift::Auto, EdgeShift::Fixed(5)] {
        let s = scene(e);
        assert!(s.bih_stats.depth >= 3);
        let d = folder(&s);
        let loaded = SceneRoms::load(d.path()).unwrap();
        // A fixed E read back as `auto` before (its JSON is {"fixed": 5}, not a number).
        assert_eq!(loaded.params, s.params);
        assert_eq!(loaded.hash(), SceneRoms::of(&s).hash());
    }
}

/// A count width of 2^32 − 1 wrapped the layout's sum (in release), passed the layout
/// check and hung the printer on a 4-Gbit signal.
#[test]
fn a_count_width_beyond_the_leaf_table_is_refused() {
    let s = scene(EdgeShift::Auto);
    let d = folder(&s);
    edit_json(d.path(), |j| {
        let node = j["roms"].as_array_mut().unwrap().iter_mut().find(|r| r["rom"] == "node").unwrap();
        let count = node["fields"].as_array_mut().unwrap().iter_mut().find(|f| f["name"] == "count").unwrap();
        count["width"] = 4294967295u32.into();
    });
    refused(d.path(), "scene.json", "count field is 4294967295 bits; 6 leaf entries need 1 to 3");
}

#[test]
fn a_bih_that_is_no_tree_is_refused() {
    let s = scene(EdgeShift::Auto);
    let nodes = s.bih.nodes.len() as i128;
    let first_leaf = s.bih.nodes.iter().position(|n| matches!(n, super::super::bih::Node::Leaf { .. })).unwrap();
    let cases: &[(Fields, usize, &str)] = &[
        (&[("child", 0)], 0, "node.hex:2: word 1: inner node 0: its children 0 and 1 must lie after it"),
        (&[("child", nodes - 1)], 0, &format!("children {} and {nodes} must lie after it, below {nodes}", nodes - 1)),
        (&[("child", 3)], 0, "node.hex:3: word 2: node 1 is the child of 0 inner nodes"),
        (&[("count", 1), ("first", 6)], first_leaf, "leaf entries 6..7 run beyond the 6 of the leaf table"),
    ];
    for (fields, k, want) in cases {
        let d = folder(&s);
        edit_word(d.path(), &s, 1, *k, fields);
        let file = if want.starts_with("node.hex:") { "" } else { "node.hex" };
        refused(d.path(), file, want);
    }
    // Two parents: a leaf made an inner node over another inner node's children after it.
    let (leaf, c) = s
        .bih
        .nodes
        .iter()
        .enumerate()
        .find_map(|(l, n)| {
            let later = s.bih.nodes.iter().find_map(|m| match *m {
                super::super::bih::Node::Inner { child, .. } if child as usize > l => Some(child),
                _ => None,
            });
            matches!(n, super::super::bih::Node::Leaf { .. }).then_some(()).and(later).map(|c| (l, c))
        })
        .unwrap();
    let d = folder(&s);
    edit_word(d.path(), &s, 1, leaf, &[("axis", 0), ("clip0", 0), ("clip1", 0), ("child", c as i128)]);
    refused(d.path(), "", &format!("node.hex:{}: word {}: node {c} is the child of 2 inner nodes", c + 2, c + 1));
    // Deeper than the stack the parameters give.
    let d = folder(&s);
    edit_json(d.path(), |j| j["params"]["stack_depth"] = 2.into());
    refused(d.path(), "node.hex", "lies deeper than the stack of 2 entries");
}

#[test]
fn values_outside_what_quantisation_writes_are_refused() {
    let s = scene(EdgeShift::Auto);
    let f = 1i128 << 15;
    let cases: &[(usize, Fields, &str)] = &[
        (0, &[("r", 3)], "tri.hex:2: word 1: the projection axis r is 3"),
        (0, &[("np", -f)], "np = -32768 is beyond ±(2^F − 1) = ±32767"),
        (0, &[("d", -(3 << 12) - 2)], "plane offset d = -12290 is beyond"),
        (2, &[("tri", 7)], "leaf.hex:2: word 1: triangle 7 is not in the table of 6"),
    ];
    for (rom, fields, want) in cases {
        let d = folder(&s);
        edit_word(d.path(), &s, *rom, 0, fields);
        refused(d.path(), "", want);
    }
}

#[test]
fn malformed_words_and_headers_name_their_file() {
    let s = scene(EdgeShift::Fixed(5));
    let d = folder(&s);
    let node = d.path().join("node.hex");
    let text = std::fs::read_to_string(&node).unwrap();
    let digits = text.lines().nth(1).unwrap().len();
    // A set bit above the word's width (the first digit holds its top bits).
    let width = rom::layouts(&s)[1].width;
    assert!(!width.is_multiple_of(4));
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    lines[1].replace_range(..1, "f");
    std::fs::write(&node, lines.join("\n")).unwrap();
    refused(d.path(), "node.hex:2", "has bits set above the word's 30 bits");
    std::fs::write(&node, text.replacen('\n', "\n0", 2)).unwrap();
    refused(d.path(), "node.hex:2", &format!("is not {digits} hex digits"));
    std::fs::write(&node, text.lines().take(2).collect::<Vec<_>>().join("\n")).unwrap();
    refused(d.path(), "node.hex", "has 1 words; scene.json gives the node ROM");
    type Edit = Box<dyn Fn(&mut serde_json::Value)>;
    let cases: Vec<(Edit, &str)> = vec![
        (Box::new(|j| j["edge_shift_used"] = 99.into()), "edge_shift_used 99 is above 98"),
        (Box::new(|j| j["edge_shift_used"] = 6.into()), "is not the fixed edge shift 5"),
        (Box::new(|j| j["scene"] = "a\nb".into()), "control character"),
        (Box::new(|j| j["params"]["n"] = 41.into()), "params: --n: 41 is out of range"),
        (Box::new(|j| j["grid_box_hi"][1] = (-1).into()), "grid_box_hi does not fit"),
    ];
    for (edit, want) in cases {
        let d = folder(&s);
        edit_json(d.path(), edit);
        refused(d.path(), "scene.json", want);
    }
}
