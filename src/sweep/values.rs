//! The values one sweep parameter takes: `--n 20..29`, `--m 12,16,20`, `--t 0..24:8`,
//! `--edge-shift auto,8..12:2`, `--slots 8..64:8`. Ranges are inclusive; `:STEP` sets the
//! stride (default 1). Every value is checked against `params::RANGES` (the core's shape
//! against `CORE_RANGES`) here, before anything runs.

use crate::error::{Error, Result};
use crate::params::{EdgeShift, RANGES};

/// The core's shape (`CoreParams::check`'s limits): ray slots per traversal unit, traversal
/// units; and with `--memory external` the memory model's latency and the caches' sizes
/// (`MemoryTiming::validate`'s and `check_cache_kb`'s limits).
pub const CORE_RANGES: &[(&str, u32, u32)] = &[
    ("slots", 1, 64),
    ("units", 1, crate::cores::core_params::MAX_UNITS),
    ("mem-latency", 1, crate::verify::memory::MAX_LATENCY),
    ("node-cache-kb", 1, 4096),
    ("tri-cache-kb", 1, 4096),
];

/// Parses a list of unsigned values and ranges for parameter `name` (as in `params::RANGES`
/// or `CORE_RANGES`), keeping the order given and dropping repeats.
pub fn parse_u32_list(name: &str, text: &str) -> Result<Vec<u32>> {
    let (_, lo, hi) = RANGES.iter().chain(CORE_RANGES).find(|r| r.0 == name).copied().expect("known parameter");
    let err = |msg: String| Error::param(name, msg);
    let mut out: Vec<u32> = Vec::new();
    for item in text.split(',').map(str::trim) {
        if item.is_empty() {
            return Err(err(format!("'{text}' has an empty item: write values or ranges like 8,10..12")));
        }
        for v in expand_item(item, lo, hi).map_err(err)? {
            if !out.contains(&v) {
                out.push(v);
            }
        }
    }
    Ok(out)
}

/// Like `parse_u32_list`, for the edge shift: items may also be `auto`.
pub fn parse_edge_shift_list(text: &str) -> Result<Vec<EdgeShift>> {
    let mut out = Vec::new();
    for item in text.split(',').map(str::trim) {
        let values = if item.eq_ignore_ascii_case("auto") {
            vec![EdgeShift::Auto]
        } else {
            parse_u32_list("edge-shift", item)?.into_iter().map(EdgeShift::Fixed).collect()
        };
        for v in values {
            if !out.contains(&v) {
                out.push(v);
            }
        }
    }
    Ok(out)
}

/// One item: `V`, `A..B` or `A..B:S` (inclusive), every value in lo..=hi. Errors say what is
/// wrong with the item; the bounds are checked before a range is expanded.
fn expand_item(item: &str, lo: u32, hi: u32) -> std::result::Result<Vec<u32>, String> {
    let in_range = |v: u32| {
        if v < lo || v > hi { Err(format!("{v} (in '{item}') is out of range: must be {lo}..={hi}")) } else { Ok(v) }
    };
    let number = |s: &str| -> std::result::Result<u32, String> {
        s.trim().parse::<u32>().map_err(|_| format!("'{s}' (in '{item}') is not a non-negative integer"))
    };
    let Some((a, rest)) = item.split_once("..") else {
        return Ok(vec![in_range(number(item)?)?]);
    };
    let rest = rest.strip_prefix('=').unwrap_or(rest);
    let (b, step) = match rest.split_once(':') {
        Some((b, s)) => (b, number(s)?),
        None => (rest, 1),
    };
    let (a, b) = (number(a)?, number(b)?);
    in_range(a)?;
    in_range(b)?;
    if step == 0 {
        return Err(format!("'{item}' has step 0"));
    }
    if a > b {
        return Err(format!("'{item}' is reversed: write {b}..{a}"));
    }
    Ok((a..=b).step_by(step as usize).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_ranges_and_steps() {
        assert_eq!(parse_u32_list("n", "20..23").unwrap(), vec![20, 21, 22, 23]);
        assert_eq!(parse_u32_list("t", "0..24:8").unwrap(), vec![0, 8, 16, 24]);
        assert_eq!(parse_u32_list("m", "12, 16,20,16").unwrap(), vec![12, 16, 20]);
        assert_eq!(parse_u32_list("c", "8..=9,12").unwrap(), vec![8, 9, 12]);
        assert_eq!(
            parse_edge_shift_list("auto,8..12:2").unwrap(),
            vec![EdgeShift::Auto, EdgeShift::Fixed(8), EdgeShift::Fixed(10), EdgeShift::Fixed(12)]
        );
    }

    #[test]
    fn bad_lists_name_the_parameter_and_the_problem() {
        let e = parse_u32_list("n", "29..20").unwrap_err().to_string();
        assert_eq!(e, "--n: '29..20' is reversed: write 20..29");
        let e = parse_u32_list("n", "20..41").unwrap_err().to_string();
        assert_eq!(e, "--n: 41 (in '20..41') is out of range: must be 4..=40");
        assert!(parse_u32_list("m", "").unwrap_err().to_string().contains("empty item"));
        assert!(parse_u32_list("m", "12,,16").unwrap_err().to_string().contains("empty item"));
        assert!(parse_u32_list("t", "0..8:0").unwrap_err().to_string().contains("step 0"));
        assert!(parse_u32_list("c", "x").unwrap_err().to_string().contains("not a non-negative integer"));
        // Checked before expanding: no four-billion-element list.
        let e = parse_u32_list("t", "0..4000000000").unwrap_err().to_string();
        assert_eq!(e, "--t: 4000000000 (in '0..4000000000') is out of range: must be 0..=62");
        assert!(parse_edge_shift_list("auto,200").unwrap_err().to_string().starts_with("--edge-shift: 200"));
    }
}
