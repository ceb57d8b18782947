//! What `SceneRoms::load` checks of a scene folder before anything is built from it. The core
//! is wired from these words, so every value must be one fxrt itself could have written: the
//! widths the parameters and table sizes imply, triangle fields in the ranges quantisation
//! keeps, a BIH that is a tree (children after their parent, every node but the root some
//! node's child, no deeper than the hardware stack), leaves inside the leaf table and leaf
//! entries naming stored triangles. Arithmetic on read values is done in u128/i128 or
//! checked, so no value read can wrap a test into passing.

use super::rom::{Layout, Word, value_bits};
use crate::error::{Error, Result};
use crate::params::{EdgeShift, Params};
use std::path::{Path, PathBuf};

/// A `$readmemh` file as `rom::readmemh` writes it: `//` comment lines, then one word a line.
pub(super) struct HexFile {
    pub path: PathBuf,
    /// (line number, the word's digits) of every word line, in order.
    lines: Vec<(usize, String)>,
}

impl HexFile {
    /// Reads `dir/<name>.hex`; a file with no words is an error.
    pub fn read(dir: &Path, name: &str) -> Result<HexFile> {
        let path = dir.join(format!("{name}.hex"));
        let text = std::fs::read_to_string(&path).map_err(|e| Error::file(&path, e.to_string()))?;
        let lines: Vec<(usize, String)> = text
            .lines()
            .enumerate()
            .filter(|(_, x)| !x.starts_with("//") && !x.trim().is_empty())
            .map(|(i, x)| (i + 1, x.trim().to_string()))
            .collect();
        if lines.is_empty() {
            return Err(Error::file(&path, "has no words"));
        }
        Ok(HexFile { path, lines })
    }

    pub fn len(&self) -> usize {
        self.lines.len()
    }

    /// The problem `message` with word `k` (0-based): `path:line: word k+1: message`.
    pub fn at(&self, k: usize, message: impl std::fmt::Display) -> Error {
        Error::file_line(&self.path, self.lines[k].0, format!("word {}: {message}", k + 1))
    }

    /// The words, each exactly ⌈width/4⌉ hex digits with no bit set at or above `width`.
    pub fn words(&self, layout: &Layout) -> Result<Vec<Word>> {
        let digits = layout.width.div_ceil(4) as usize;
        let mut words = Vec::with_capacity(self.lines.len());
        for (k, (_, text)) in self.lines.iter().enumerate() {
            let word = Word::from_hex(text)
                .filter(|_| text.len() == digits)
                .ok_or_else(|| self.at(k, format!("'{}' is not {digits} hex digits", clip(text))))?;
            if (layout.width..4 * digits as u32).any(|b| bit(&word, b)) {
                return Err(self.at(k, format!("'{text}' has bits set above the word's {} bits", layout.width)));
            }
            words.push(word);
        }
        Ok(words)
    }
}

/// At most 40 characters of a word, so a huge line does not make a huge message.
fn clip(text: &str) -> String {
    match text.char_indices().nth(40) {
        Some((i, _)) => format!("{}…", &text[..i]),
        None => text.to_string(),
    }
}

fn bit(w: &Word, b: u32) -> bool {
    w.0.get((b / 64) as usize).is_some_and(|limb| (limb >> (b % 64)) & 1 == 1)
}

/// The scene's name, parameters, edge shift and box, as scene.json gives them.
pub(super) fn header(json: &Path, name: &str, params: &Params, edge_shift: u32, box_hi: &[i64; 3]) -> Result<()> {
    let bad = |msg: String| Err(Error::file(json, msg));
    // The name goes into comments of the HDL and the ISE project's TCL, one line each.
    if name.chars().any(char::is_control) {
        return bad(format!("the scene name {name:?} has a control character"));
    }
    params.validate().map_err(|e| Error::file(json, format!("params: {e}")))?;
    let max = params.max_edge_shift();
    if edge_shift > max {
        return bad(format!(
            "edge_shift_used {edge_shift} is above {max}, the largest for n = {}, m = {}",
            params.n, params.m
        ));
    }
    if let EdgeShift::Fixed(e) = params.edge_shift
        && e != edge_shift
    {
        return bad(format!("edge_shift_used {edge_shift} is not the fixed edge shift {e} of params"));
    }
    if box_hi.iter().any(|&h| h < 0 || h >= 1i64 << params.n) {
        return bad(format!("grid_box_hi does not fit {} bits", params.n));
    }
    Ok(())
}

/// The node ROM's count width read from scene.json, before any layout is computed from it: a
/// leaf holds at most every leaf entry, so it needs no more bits than their number (a width of
/// 2^32 − 1 used to wrap the layout's sum and hang the HDL printer).
pub(super) fn count_width(json: &Path, count_bits: u32, leaf_entries: usize) -> Result<()> {
    let most = value_bits(leaf_entries);
    if count_bits == 0 || count_bits > most {
        return Err(Error::file(
            json,
            format!("the node ROM's count field is {count_bits} bits; {leaf_entries} leaf entries need 1 to {most}"),
        ));
    }
    Ok(())
}

/// Every triangle field inside the range `accel::quantize` keeps it in.
pub(super) fn triangles(hex: &HexFile, l: &Layout, words: &[Word], p: &Params) -> Result<()> {
    let lim = (1i128 << p.f()) - 1;
    let d_max = 3 * (1i128 << p.n) + 1;
    for (k, w) in words.iter().enumerate() {
        if w.get(l.field("r")) > 2 {
            return Err(hex.at(k, "the projection axis r is 3; it must be 0, 1 or 2"));
        }
        let d = w.get(l.field("d"));
        if d.abs() > d_max {
            return Err(hex.at(k, format!("the plane offset d = {d} is beyond ±(3·2^n + 1) = ±{d_max}")));
        }
        for name in ["np", "nq", "e1p", "e1q", "e2p", "e2q"] {
            let v = w.get(l.field(name));
            if v.abs() > lim {
                return Err(hex.at(k, format!("{name} = {v} is beyond ±(2^F − 1) = ±{lim}")));
            }
        }
    }
    Ok(())
}

/// The BIH: node 0 the root, each inner node's children `child`, `child + 1` after it and
/// inside the table, every other node the child of exactly one inner node (so the nodes form
/// one tree), at most `stack_depth` inner nodes on any path, each leaf's entries inside the
/// leaf table, and the bits no field of the node's kind uses zero.
pub(super) fn nodes(hex: &HexFile, l: &Layout, words: &[Word], leaf_entries: usize, stack_depth: u32) -> Result<()> {
    let count = words.len();
    let (mut parents, mut depth) = (vec![0u8; count], vec![0u32; count]);
    let end = |name: &str| l.field(name).lsb + l.field(name).width;
    for (k, w) in words.iter().enumerate() {
        let top = if w.get(l.field("axis")) == 3 {
            let (first, n) = (w.get(l.field("first")), w.get(l.field("count")));
            if first + n > leaf_entries as i128 {
                return Err(hex.at(
                    k,
                    format!("leaf entries {first}..{} run beyond the {leaf_entries} of the leaf table", first + n),
                ));
            }
            end("count")
        } else {
            let child = w.get(l.field("child"));
            if child <= k as i128 || child + 1 >= count as i128 {
                return Err(hex.at(
                    k,
                    format!("inner node {k}: its children {child} and {} must lie after it, below {count}", child + 1),
                ));
            }
            if depth[k] >= stack_depth {
                return Err(hex.at(k, format!("inner node {k} lies deeper than the stack of {stack_depth} entries")));
            }
            for c in [child as usize, child as usize + 1] {
                parents[c] = parents[c].saturating_add(1);
                // Parents come before their children, so depth[k] is final here.
                depth[c] = depth[c].max(depth[k] + 1);
            }
            end("child")
        };
        if (top..l.width).any(|b| bit(w, b)) {
            return Err(hex.at(k, format!("bits {top}..{} are not zero; no field of this node uses them", l.width)));
        }
    }
    if let Some(k) = (1..count).find(|&k| parents[k] != 1) {
        return Err(
            hex.at(k, format!("node {k} is the child of {} inner nodes; in a tree it is of exactly one", parents[k]))
        );
    }
    Ok(())
}

/// Every leaf entry names a triangle of the table.
pub(super) fn leaves(hex: &HexFile, l: &Layout, words: &[Word], tris: usize) -> Result<()> {
    for (k, w) in words.iter().enumerate() {
        let t = w.get(l.field("tri"));
        if t >= tris as i128 {
            return Err(hex.at(k, format!("triangle {t} is not in the table of {tris}")));
        }
    }
    Ok(())
}

#[cfg(test)]
#[path = "image_check_tests.rs"]
mod tests;
