//! What the hardware needs of a scene: its parameters, box and the three ROM images. Built
//! from a loaded scene, or read back from the folder `fxrt scene` wrote (scene.json and the
//! .hex files), so `fxrt gen --scene DIR` builds the core from exactly those ROM contents.

use super::Scene;
use super::image_check::{self, HexFile};
use super::rom::{self, Field, Layout, Word};
use crate::error::{Error, Result};
use crate::params::Params;
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
    depth: usize,
    fields: Vec<JsonField>,
}

/// What `load` reads of scene.json (`report::scene_json` writes more).
#[derive(Deserialize)]
struct JsonScene {
    scene: String,
    params: Params,
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

    /// Reads scene.json and tri.hex, node.hex, leaf.hex from `dir`, and checks that every
    /// layout, word and value is one fxrt writes (`image_check`) before anything is built from
    /// them. Errors name the file (and line) at fault.
    pub fn load(dir: &Path) -> Result<SceneRoms> {
        let json_path = dir.join("scene.json");
        let text = std::fs::read_to_string(&json_path).map_err(|e| Error::file(&json_path, e.to_string()))?;
        let j: JsonScene = serde_json::from_str(&text).map_err(|e| Error::file(&json_path, e.to_string()))?;
        let params = j.params;
        image_check::header(&json_path, &j.scene, &params, j.edge_shift_used, &j.grid_box_hi)?;
        let hex = [HexFile::read(dir, "tri")?, HexFile::read(dir, "node")?, HexFile::read(dir, "leaf")?];
        let mut json_layouts = Vec::new();
        for (&name, file) in ["tri", "node", "leaf"].iter().zip(&hex) {
            let l = j
                .roms
                .iter()
                .find(|r| r.rom == name)
                .ok_or_else(|| Error::file(&json_path, format!("no layout of the {name} ROM")))?;
            if l.depth != file.len() {
                let msg = format!("has {} words; scene.json gives the {name} ROM {}", file.len(), l.depth);
                return Err(Error::file(&file.path, msg));
            }
            json_layouts.push(Layout { rom: name, width: l.width, depth: l.depth, fields: fields(&json_path, l)? });
        }
        // The hardware is wired from these layouts: they must be exactly the ones fxrt writes
        // for these parameters and table sizes (a reordered or resized field is an error). The
        // count width comes from the file, so it is bounded before any width is summed.
        let count_bits = json_layouts[1].fields.iter().find(|f| f.name == "count").map_or(1, |f| f.width);
        image_check::count_width(&json_path, count_bits, hex[2].len())?;
        let expected = rom::layouts_for(params.n, params.m, hex[0].len(), hex[1].len(), hex[2].len(), count_bits);
        for (got, want) in json_layouts.iter().zip(&expected) {
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
        let [tri_l, node_l, leaf_l] = expected;
        let tri_w = hex[0].words(&tri_l)?;
        let node_w = hex[1].words(&node_l)?;
        let leaf_w = hex[2].words(&leaf_l)?;
        image_check::triangles(&hex[0], &tri_l, &tri_w, &params)?;
        image_check::nodes(&hex[1], &node_l, &node_w, leaf_w.len(), params.stack_depth)?;
        image_check::leaves(&hex[2], &leaf_l, &leaf_w, tri_w.len())?;
        Ok(SceneRoms {
            name: j.scene,
            params,
            edge_shift: j.edge_shift_used,
            box_hi: j.grid_box_hi,
            tri: (tri_l, tri_w),
            node: (node_l, node_w),
            leaf: (leaf_l, leaf_w),
        })
    }
}

/// A ROM's fields as scene.json lists them, named by the layouts' own names.
fn fields(json_path: &Path, l: &JsonRom) -> Result<Vec<Field>> {
    l.fields
        .iter()
        .map(|f| {
            let name = FIELD_NAMES
                .iter()
                .chain(&["count", "tri"])
                .find(|n| **n == f.name)
                .ok_or_else(|| Error::file(json_path, format!("unknown ROM field '{}'", f.name)))?;
            Ok(Field { name, lsb: f.lsb, width: f.width, signed: f.signed })
        })
        .collect()
}
