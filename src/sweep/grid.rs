//! Image grids like seed 001 figures 2.7 (m), 2.8 (T) and 2.9 (C): one scene, one parameter
//! varied, the others at the base set; renders on top, error maps below.

use super::draw::{FONT, register_font};
use super::eval::Row;
use super::output::{Results, cached_images};
use super::{Axis, Plan};
use crate::error::{Error, Result};
use crate::io::OutputSet;
use crate::render::encode_png;
use plotters::prelude::*;
use std::path::Path;

/// Tiles wider than this are shrunk by an integer factor.
const MAX_TILE: u32 = 256;
/// Tiles per row of the grid.
const COLUMNS: usize = 8;
const LABEL_H: u32 = 40;
const TITLE_H: u32 = 34;
const GAP: u32 = 6;

/// The rows of one scene where only `axis` differs from the base set, in list order.
pub fn series<'a>(results: &'a Results, plan: &Plan, scene: &str, axis: Axis) -> Vec<&'a Row> {
    let others: Vec<Axis> = Axis::ALL.into_iter().filter(|&a| a != axis).collect();
    let values = results.spec.values(axis);
    let mut rows: Vec<&Row> = results
        .rows
        .iter()
        .filter(|r| r.scene == scene && others.iter().all(|a| a.value(&r.set()) == a.value(&plan.base)))
        .collect();
    rows.sort_by_key(|r| values.iter().position(|v| *v == axis.value(&r.set())));
    rows
}

/// Stages grids/SCENE_PARAM.png for every scene and swept parameter that can change the image
/// (not the core's shape); returns their paths.
pub fn add_grids(
    files: &mut OutputSet,
    dir: &Path,
    cache: &Path,
    results: &Results,
    plan: &Plan,
) -> Result<Vec<String>> {
    let mut written = Vec::new();
    for scene in super::scene_labels(&results.spec.scenes) {
        for axis in results.spec.swept_axes().into_iter().filter(|a| a.changes_image()) {
            let rows = series(results, plan, &scene, axis);
            if rows.len() < 2 {
                continue;
            }
            let png = grid_png(cache, &scene, axis, &rows)?;
            let rel = format!("grids/{scene}_{}.png", axis.name());
            files.add(&dir.join(&rel), &png)?;
            written.push(rel);
        }
    }
    Ok(written)
}

struct Tile {
    w: u32,
    h: u32,
    rgb: Vec<u8>,
}

fn decode(bytes: &[u8], what: &str) -> Result<Tile> {
    let bad = |e: String| Error::new(what.to_string(), format!("cannot read the cached image: {e}"));
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().map_err(|e| bad(e.to_string()))?;
    let mut buf = vec![0; reader.output_buffer_size().unwrap_or(0)];
    let info = reader.next_frame(&mut buf).map_err(|e| bad(e.to_string()))?;
    if info.color_type != png::ColorType::Rgb || info.bit_depth != png::BitDepth::Eight {
        return Err(bad("not 8-bit RGB".into()));
    }
    buf.truncate(info.buffer_size());
    Ok(shrink(Tile { w: info.width, h: info.height, rgb: buf }))
}

/// Box filter by the smallest integer factor that brings the width to MAX_TILE or less.
fn shrink(t: Tile) -> Tile {
    let k = t.w.div_ceil(MAX_TILE).max(1);
    if k == 1 {
        return t;
    }
    let (w, h) = (t.w / k, t.h / k);
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    for y in 0..h {
        for x in 0..w {
            for ch in 0..3 {
                let mut sum = 0u32;
                for dy in 0..k {
                    for dx in 0..k {
                        sum += t.rgb[(((y * k + dy) * t.w + x * k + dx) * 3 + ch) as usize] as u32;
                    }
                }
                rgb[((y * w + x) * 3 + ch) as usize] = (sum / (k * k)) as u8;
            }
        }
    }
    Tile { w, h, rgb }
}

fn grid_png(cache: &Path, scene: &str, axis: Axis, rows: &[&Row]) -> Result<Vec<u8>> {
    let mut tiles = Vec::new();
    for r in rows {
        tiles.push(match r.quality {
            Some(_) => {
                let (png, errors) = cached_images(cache, &r.key)?;
                Some((decode(&png, &r.key)?, decode(&errors, &r.key)?))
            }
            None => None,
        });
    }
    let (tw, th) = tiles.iter().flatten().map(|(t, _)| (t.w, t.h)).next().unwrap_or((MAX_TILE, MAX_TILE));
    let cols = rows.len().min(COLUMNS) as u32;
    let grid_rows = rows.len().div_ceil(COLUMNS) as u32;
    let cell_w = tw.max(150) + GAP;
    let cell_h = 2 * th + GAP + LABEL_H;
    // Wide enough for the title, however small the tiles.
    let (w, h) = ((cols * cell_w + GAP).max(480), TITLE_H + grid_rows * cell_h + GAP);
    let mut rgb = vec![255u8; (w * h * 3) as usize];
    let mut blit = |t: &Tile, x0: u32, y0: u32| {
        for y in 0..t.h {
            let src = &t.rgb[(y * t.w * 3) as usize..((y + 1) * t.w * 3) as usize];
            let at = (((y0 + y) * w + x0) * 3) as usize;
            rgb[at..at + src.len()].copy_from_slice(src);
        }
    };
    let placeholder = Tile { w: tw, h: th, rgb: [60u8, 60, 60].repeat((tw * th) as usize) };
    for (i, t) in tiles.iter().enumerate() {
        let (x0, y0) = (GAP + (i % COLUMNS) as u32 * cell_w, TITLE_H + (i / COLUMNS) as u32 * cell_h);
        let (render, errors) = t.as_ref().map(|(a, b)| (a, b)).unwrap_or((&placeholder, &placeholder));
        blit(render, x0, y0);
        blit(errors, x0, y0 + th + GAP / 2);
    }
    register_font();
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        let draw = |text: String, x: u32, y: u32, size: u32| {
            root.draw(&Text::new(text, (x as i32, y as i32), (FONT, size).into_font().color(&BLACK)))
                .map_err(|e| Error::new("sweep grid", e.to_string()))
        };
        draw(format!("{scene}: {} varied (renders above, errors below)", axis.symbol()), GAP, 8, 18)?;
        for (i, r) in rows.iter().enumerate() {
            let (x0, y0) = (GAP + (i % COLUMNS) as u32 * cell_w, TITLE_H + (i / COLUMNS) as u32 * cell_h);
            let y = y0 + 2 * th + GAP;
            draw(format!("{} = {}", axis.symbol(), axis.value(&r.set())), x0, y, 15)?;
            let detail = match &r.quality {
                Some(q) => format!("{} wrong px, {} differ", q.wrong_pixels, q.diff_vs_default),
                None => "failed".to_string(),
            };
            draw(detail, x0, y + 18, 13)?;
        }
        root.present().map_err(|e| Error::new("sweep grid", e.to_string()))?;
    }
    Ok(encode_png(w, h, &rgb))
}
