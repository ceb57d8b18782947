//! What the hardware needs of a scene: its parameters, box and the three ROM images. Built
//! from a loaded scene, or read back from the folder `fxrt scene` wrote (scene.json and the
//! .hex files), so `fxrt gen --scene DIR` builds the core from exactly those ROM contents.

use super::Scene;
use super::rom::{self, Field, Layout, Word};
use crate::error::{Error, Result};
use crate::params::{EdgeShift, Params, TreeSplit};
use serde::Deserialize;
use std::path::Path;

#[derive(Clone, Debug)]
pub struct SceneRoms {
    pub name: String,
    pub params: Params,
    pub edge_shift: u32,
    pub box_hi: [i64; 3],
    pub tri: (Layout, Vec<Word>),
    pub node: (Layout, Vec<Word>),
    pub leaf: (Layout, Vec<Word>),
}

#[derive(Deserialize)]
struct JsonField {
    name: String,
    lsb: u32,
    width: u32,
    signed: bool,
}

#[derive(Deserialize)]
struct JsonRom {
    rom: String,
    width: u32,
    fields: Vec<JsonField>,
}

#[derive(Deserialize)]
struct JsonParams {
    n: u32,
    m: u32,
    t: u32,
    c: u32,
    leaf_size: u32,
    stack_depth: u32,
    #[serde(default)]
    tree: TreeSplit,
    edge_shift: serde_json::Value,
}

#[derive(Deserialize)]
struct JsonScene {
    scene: String,
    params: JsonParams,
    edge_shift_used: u32,
    grid_box_hi: [i64; 3],
    roms: Vec<JsonRom>,
}

/// Field names as the layouts spell them (layouts hold `&'static str`).
const FIELD_NAMES: [&str; 15] =
    ["r", "pp", "pq", "d", "np", "nq", "e1p", "e1q", "e2p", "e2q", "axis", "clip0", "clip1", "child", "first"];

impl SceneRoms {
    /// SHA-256 (hex) of what the hardware holds of the scene: its parameters, box, edge shift
    /// and every ROM's layout and words. Two builds with the same hash have the same ROMs.
    pub fn hash(&self) -> String {
        use sha2::{Digest, Sha256};
        let mut h = Sha256::new();
        h.update(format!("{:?} {:?} {}", self.params, self.box_hi, self.edge_shift).as_bytes());
        for (layout, words) in [&self.tri, &self.node, &self.leaf] {
            h.update(format!("{:?}", layout).as_bytes());
            for w in words {
                for x in &w.0 {
                    h.update(x.to_le_bytes());
                }
            }
        }
        format!("{:x}", h.finalize())
    }

    /// The short scene tag in the names of the modules that depend on the scene: `s` and the
    /// first six hex digits of `hash`, so two scenes' cores can share one project.
    pub fn tag(&self) -> String {
        format!("s{}", &self.hash()[..6])
    }

    pub fn of(scene: &Scene) -> SceneRoms {
        let [tri, node, leaf] = rom::words(scene);
        SceneRoms {
            name: scene.name.clone(),
            params: scene.params,
            edge_shift: scene.edge_shift,
            box_hi: scene.grid_box.hi,
            tri,
            node,
            leaf,
        }
    }

    pub fn tri_count(&self) -> usize {
        self.tri.1.len()
    }

    /// Bits of the three ROMs as printed (each rounded up to a power-of-two depth).
    pub fn rom_bits(&self) -> u64 {
        [&self.tri, &self.node, &self.leaf]
            .iter()
            .map(|(l, w)| l.width as u64 * crate::scene::rom::rom_depth(w.len()) as u64)
            .sum()
    }

    /// Reads scene.json and tri.hex, node.hex, leaf.hex from `dir`.
    pub fn load(dir: &Path) -> Result<SceneRoms> {
        let json_path = dir.join("scene.json");
        let text = std::fs::read_to_string(&json_path).map_err(|e| Error::file(&json_path, e.to_string()))?;
        let j: JsonScene = serde_json::from_str(&text).map_err(|e| Error::file(&json_path, e.to_string()))?;
        let edge_shift = match &j.params.edge_shift {
            serde_json::Value::Number(v) => EdgeShift::Fixed(v.as_u64().unwrap_or(0) as u32),
            _ => EdgeShift::Auto,
        };
        let p = &j.params;
        let params = Params {
            n: p.n,
            m: p.m,
            edge_shift,
            t: p.t,
            c: p.c,
            leaf_size: p.leaf_size,
            stack_depth: p.stack_depth,
            tree: p.tree,
        };
        params.validate().map_err(|e| Error::file(&json_path, e.to_string()))?;
        let mut images = Vec::new();
        for name in ["tri", "node", "leaf"] {
            let l = j
                .roms
                .iter()
                .find(|r| r.rom == name)
                .ok_or_else(|| Error::file(&json_path, format!("no layout of the {name} ROM")))?;
            let fields = l
                .fields
                .iter()
                .map(|f| {
                    let name = FIELD_NAMES
                        .iter()
                        .chain(&["count", "tri"])
                        .find(|n| **n == f.name)
                        .ok_or_else(|| Error::file(&json_path, format!("unknown ROM field '{}'", f.name)))?;
                    Ok(Field { name, lsb: f.lsb, width: f.width, signed: f.signed })
                })
                .collect::<Result<Vec<_>>>()?;
            let hex = dir.join(format!("{name}.hex"));
            let text = std::fs::read_to_string(&hex).map_err(|e| Error::file(&hex, e.to_string()))?;
            let digits = l.width.div_ceil(4) as usize;
            let words = text
                .lines()
                .filter(|x| !x.starts_with("//") && !x.trim().is_empty())
                .enumerate()
                .map(|(i, x)| {
                    let x = x.trim();
                    Word::from_hex(x)
                        .filter(|_| x.len() == digits)
                        .ok_or_else(|| Error::file(&hex, format!("word {}: '{x}' is not {digits} hex digits", i + 1)))
                })
                .collect::<Result<Vec<Word>>>()?;
            if words.is_empty() {
                return Err(Error::file(&hex, "has no words"));
            }
            let rom_name = match name {
                "tri" => "tri",
                "node" => "node",
                _ => "leaf",
            };
            images.push((Layout { rom: rom_name, width: l.width, depth: words.len(), fields }, words));
        }
        // The hardware is wired from these layouts: they must be exactly the ones fxrt writes
        // for these parameters and table sizes (a reordered or resized field is an error).
        let count_bits = images[1].0.fields.iter().find(|f| f.name == "count").map_or(0, |f| f.width);
        let expected = rom::layouts_for(
            params.n,
            params.m,
            images[0].1.len(),
            images[1].1.len(),
            images[2].1.len(),
            count_bits.max(1),
        );
        for ((got, _), want) in images.iter().zip(&expected) {
            if got.width != want.width || got.fields != want.fields {
                return Err(Error::file(
                    &json_path,
                    format!(
                        "the {} ROM layout is not the one fxrt writes for n = {}, m = {} and {} words",
                        got.rom, params.n, params.m, got.depth
                    ),
                ));
            }
        }
        if j.grid_box_hi.iter().any(|&h| h < 0 || h >= 1i64 << params.n) {
            return Err(Error::file(&json_path, format!("grid_box_hi does not fit {} bits", params.n)));
        }
        let leaf = images.pop().expect("three images");
        let node = images.pop().expect("three images");
        let tri = images.pop().expect("three images");
        Ok(SceneRoms { name: j.scene, params, edge_shift: j.edge_shift_used, box_hi: j.grid_box_hi, tri, node, leaf })
    }
}
