//! All or nothing on disk: a command that fails (exit 2, one line naming the file) leaves none
//! of the files it would have written, and the files it would have replaced as they were.
//! Tests run as root, so permission bits stop nothing: writes are made to fail with a path
//! under a regular file, or with a target that is an existing folder.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn fxrt(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fxrt")).args(args).output().expect("fxrt runs")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Every file and folder under `dir`, relative, sorted.
fn tree(dir: &Path) -> Vec<String> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<String>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            out.push(p.strip_prefix(root).unwrap().display().to_string());
            if p.is_dir() {
                walk(root, &p, out);
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// Exit 2 and one line on stderr naming `subject`.
fn assert_fails(args: &[&str], subject: &str) -> String {
    let o = fxrt(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?} printed more than one line: {err}");
    assert!(err.contains(subject), "{args:?}: {err:?} should name {subject}");
    assert!(!err.contains(".tmp") && !err.contains(".fxrt-"), "{args:?} names a temporary file: {err}");
    err
}

/// A small sweep: two configurations of 8x8 pixels.
const SWEEP: [&str; 7] = ["sweep", "--builtin", "cornell", "--m", "16,20", "--size", "8x8"];

/// A scratch folder whose name holds no `.tmp` (tempfile's default), so an error naming a
/// temporary file stands out.
fn scratch() -> tempfile::TempDir {
    tempfile::Builder::new().prefix("fxrt-outputs-").tempdir().unwrap()
}

/// A folder holding a regular file `F`: any path `F/...` cannot be written, even by root.
fn with_blocker() -> (tempfile::TempDir, PathBuf) {
    let dir = scratch();
    let blocker = dir.path().join("F");
    std::fs::write(&blocker, b"a file").unwrap();
    (dir, blocker)
}

/// Runs `args`, a command writing into `out`, with its file `blocked` (a path below `out`) an
/// existing folder: it fails naming that file and leaves nothing in `out` but the folder.
fn assert_blocked(args: &[&str], out: &Path, blocked: &str) {
    std::fs::create_dir_all(out.join(blocked)).unwrap();
    assert_fails(args, blocked);
    let folders: Vec<String> =
        Path::new(blocked).ancestors().filter(|a| !a.as_os_str().is_empty()).map(|a| a.display().to_string()).collect();
    assert_eq!(tree(out), folders.into_iter().rev().collect::<Vec<_>>(), "{args:?} left files in {}", out.display());
}

#[test]
fn render_writes_none_of_its_files_when_one_cannot_be_written() {
    let (dir, blocker) = with_blocker();
    let d = dir.path();
    let (png, ids, depth) = (d.join("o.png"), d.join("ids.bin"), blocker.join("d.bin"));
    let render = ["render", "--builtin", "cornell", "--size", "16x16"];
    let args = [&render[..], &["--png", s(&png), "--ids", s(&ids), "--depth", s(&depth)]].concat();
    assert_fails(&args, "F");
    assert_eq!(tree(d), ["F"]);
    // A target that is a folder is refused the same way.
    let folder = d.join("depth-folder");
    std::fs::create_dir(&folder).unwrap();
    let args = [&render[..], &["--png", s(&png), "--ids", s(&ids), "--depth", s(&folder)]].concat();
    assert_fails(&args, "depth-folder");
    assert_eq!(tree(d), ["F", "depth-folder"]);
    // Files it would have replaced keep their old contents.
    std::fs::write(&png, b"old picture").unwrap();
    let args = [&render[..], &["--png", s(&png), "--depth", s(&depth)]].concat();
    assert_fails(&args, "F");
    assert_eq!(std::fs::read(&png).unwrap(), b"old picture");
    // Two options naming one file would have the second overwrite the first.
    let args = [&render[..], &["--ids", s(&ids), "--depth", s(&ids)]].concat();
    assert_fails(&args, "ids.bin");
    assert!(!ids.exists());
}

#[test]
fn sim_writes_no_picture_when_its_ids_cannot_be_written() {
    let (dir, blocker) = with_blocker();
    let d = dir.path();
    let (png, ids) = (d.join("o.png"), blocker.join("ids.bin"));
    let args = ["sim", "--builtin", "cornell", "--size", "8x8", "--png", s(&png), "--ids", s(&ids)];
    assert_fails(&args, "F");
    assert_eq!(tree(d), ["F"]);
}

#[test]
fn scene_writes_no_rom_image_when_scene_json_cannot_be_written() {
    let dir = scratch();
    let out = dir.path().join("s");
    assert_blocked(&["scene", "--builtin", "cornell", "--out", s(&out)], &out, "scene.json");
    // An --out below a file: nothing at all, and the one line names it.
    let (dir, blocker) = with_blocker();
    assert_fails(&["scene", "--builtin", "cornell", "--out", s(&blocker.join("rom"))], "F");
    assert_eq!(tree(dir.path()), ["F"]);
}

#[test]
fn gen_writes_no_core_file_when_one_of_the_set_cannot_be_written() {
    let dir = scratch();
    let out = dir.path().join("hdl");
    // expected.bin, the last file of `--axis-frame`, is a folder: the core's files, written
    // before it, must not stay.
    let args = ["gen", "--builtin", "cornell", "--size", "4x4", "--axis-frame", "--ise", "--out", s(&out)];
    assert_blocked(&args, &out, "expected.bin");
}

#[test]
fn gen_board_writes_nothing_when_a_file_of_the_design_cannot_be_written() {
    let dir = scratch();
    let out = dir.path().join("ml509");
    // The board design's constraints come after its HDL.
    let probe = dir.path().join("probe");
    let o = fxrt(&["gen", "--board", "ml509", "--units", "1", "--builtin", "cornell", "--out", s(&probe)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let ucf = tree(&probe).into_iter().find(|f| f.ends_with(".ucf")).expect("a UCF");
    assert_blocked(&["gen", "--board", "ml509", "--units", "1", "--builtin", "cornell", "--out", s(&out)], &out, &ucf);
}

#[test]
fn demo_writes_no_hdl_when_its_picture_cannot_be_written() {
    let dir = scratch();
    let out = dir.path().join("demo");
    assert_blocked(&["demo", "--size", "4x4", "--out", s(&out)], &out, "hardware.png");
}

#[test]
fn sim_refuses_an_output_it_cannot_write_before_simulating() {
    let (dir, blocker) = with_blocker();
    let d = dir.path();
    let (build, png) = (d.join("build"), blocker.join("o.png"));
    // GHDL would compile and run the core in the build folder first; nothing runs.
    let args =
        ["sim", "--builtin", "cornell", "--size", "4x4", "--sim", "ghdl", "--build", s(&build), "--png", s(&png)];
    assert_fails(&args, "F");
    assert_eq!(tree(d), ["F"]);
    let below = blocker.join("b");
    let args = ["sim", "--builtin", "cornell", "--size", "4x4", "--sim", "ghdl", "--build", s(&below)];
    assert_fails(&args, "F");
}

#[test]
fn sweep_with_a_bad_out_prints_only_the_error() {
    let (dir, blocker) = with_blocker();
    let out = blocker.join("sw");
    let err = assert_fails(&["sweep", "--builtin", "cornell", "--m", "16", "--size", "8x8", "--out", s(&out)], "F");
    assert!(err.starts_with("fxrt: "), "{err}");
    assert_fails(&["sweep", "--builtin", "cornell", "--m", "16", "--size", "8x8", "--out", s(&blocker)], "F");
    let cache = blocker.join("cache");
    let sw = dir.path().join("sw");
    let args = ["sweep", "--builtin", "cornell", "--size", "8x8", "--out", s(&sw), "--cache", s(&cache)];
    assert_fails(&args, "F");
    assert_eq!(tree(dir.path()), ["F"]);
}

#[test]
fn sweep_keeps_its_cache_but_writes_no_table_when_one_cannot_be_written() {
    let dir = scratch();
    let out = dir.path().join("sw");
    std::fs::create_dir_all(out.join("report.md")).unwrap();
    let o = fxrt(&[&SWEEP[..], &["--out", s(&out)]].concat());
    // The sweep ran (its first line says so); the error is the last line.
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "{err}");
    let last = err.trim_end().lines().last().unwrap_or_default();
    assert!(last.starts_with("fxrt: ") && last.contains("report.md") && !last.contains(".fxrt-"), "{err}");
    // The finished configurations stay cached for the rerun; no table, image, grid or plot.
    let left: Vec<String> = tree(&out).into_iter().filter(|f| !f.starts_with("cache")).collect();
    assert_eq!(left, ["report.md"]);
    assert_eq!(tree(&out.join("cache")).len(), 6, "two configurations of three files each");
}

#[test]
fn sweep_merge_writes_no_table_when_one_cannot_be_written() {
    let dir = scratch();
    let d = dir.path();
    let cache = d.join("cache");
    for i in 1..=2 {
        let shard = d.join(format!("shard-{i}"));
        let sh = format!("{i}/2");
        let o = fxrt(&[&SWEEP[..], &["--shard", &sh, "--cache", s(&cache), "--out", s(&shard)]].concat());
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let out = d.join("merged");
    let (one, two) = (d.join("shard-1"), d.join("shard-2"));
    let args = ["sweep", "merge", s(&one), s(&two), "--cache", s(&cache), "--out", s(&out)];
    assert_blocked(&args, &out, "results.csv");
}

#[test]
fn sweep_emit_slurm_writes_no_script_when_one_cannot_be_written() {
    let dir = scratch();
    let out = dir.path().join("sw");
    let args = ["sweep", "--builtin", "cornell", "--m", "16,20", "--emit-slurm", "--shards", "2", "--out", s(&out)];
    assert_blocked(&args, &out, "slurm/commands.txt");
}
