//! Reading OBJ files through tobj, with the checks tobj does not make itself.
//!
//! Triangles are numbered in file order; tobj fan-splits a polygon v0,v1,v2,… into
//! (v0,vi,vi+1). These numbers are the ones every `--ids` output reports.

use super::Tri;
use super::obj_lines::{self, Fault, Found};
use crate::error::{Error, Result};
use std::path::Path;

/// Loads every face of `path` as world-space triangles in file order.
///
/// Every error names the line at fault as `path:line`. tobj does not say where it stopped, so
/// on an error the text is read a second time (`obj_lines`) for the line; loading a good file
/// costs exactly the one pass through tobj.
pub fn load_obj(path: &Path) -> Result<Vec<Tri>> {
    let bytes = std::fs::read(path).map_err(|e| Error::file(path, format!("cannot read: {e}")))?;
    parse_obj(path, &bytes)
}

/// `load_obj` of the file contents `bytes`; `path` names the file in errors.
pub fn parse_obj(path: &Path, bytes: &[u8]) -> Result<Vec<Tri>> {
    let text = match std::str::from_utf8(bytes) {
        Ok(text) => text,
        Err(e) => {
            let good = &bytes[..e.valid_up_to()];
            let line = 1 + good.iter().filter(|&&b| b == b'\n').count();
            let column = 1 + good.len() - good.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
            let at = format!("{}:{line}:{column}", path.display());
            return Err(Error::new(at, format!("not valid UTF-8 text (byte 0x{:02x})", bytes[e.valid_up_to()])));
        }
    };
    // tobj reports malformed input as errors, but we do not let a parser panic take the
    // process down either: a panic here becomes the same one-line error.
    let (models, _materials) = match quietly_catch_unwind(|| tobj_load(text.as_bytes())) {
        Some(Ok(x)) => x,
        Some(Err(e)) => {
            let found = Fault::of(&e).and_then(|f| obj_lines::locate(text, Some(f)));
            return Err(at_fault(path, found, describe_tobj_error(&e)));
        }
        None => {
            let found = obj_lines::locate(text, None);
            return Err(at_fault(path, found, "malformed OBJ (the parser gave up)".into()));
        }
    };
    let mut tris = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let pos = &mesh.positions;
        for (i, c) in pos.chunks(3).enumerate() {
            if c.iter().any(|x| !x.is_finite()) {
                let fallback = format!(
                    "vertex {} of object '{}' has a non-finite coordinate ({}, {}, {})",
                    i + 1,
                    model.name,
                    c[0],
                    c[1],
                    c[2]
                );
                return Err(at_fault(path, obj_lines::locate_non_finite(text), fallback));
            }
        }
        // tobj's meshes are consistent, so the two errors below cannot come from any text.
        let vertex = |k: u32| -> Result<[f64; 3]> {
            let k = k as usize;
            pos.get(3 * k..3 * k + 3)
                .map(|c| [c[0], c[1], c[2]])
                .ok_or_else(|| Error::file(path, format!("face index {} is out of range", k + 1)))
        };
        for f in mesh.indices.chunks(3) {
            if f.len() < 3 {
                return Err(Error::file(path, "a face has fewer than three vertices"));
            }
            tris.push([vertex(f[0])?, vertex(f[1])?, vertex(f[2])?]);
        }
    }
    if tris.is_empty() {
        return Err(Error::file_line(
            path,
            obj_lines::last_line(text),
            "no faces: the file ends without a face of three or more vertices, so the scene has no triangles",
        ));
    }
    Ok(tris)
}

/// Triangles in file order (fan-split), one index per vertex, points and lines dropped.
const OPTIONS: tobj::LoadOptions =
    tobj::LoadOptions { triangulate: true, single_index: true, ignore_points: true, ignore_lines: true };

/// Reads `text` with tobj; material files are not opened.
pub(super) fn tobj_load(text: &[u8]) -> tobj::LoadResult {
    tobj::load_obj_buf(&mut &text[..], &OPTIONS, |_| Err(tobj::LoadError::OpenFileFailed))
}

/// The error at the line found, or `fallback` naming only the file if no line was found.
fn at_fault(path: &Path, found: Option<Found>, fallback: String) -> Error {
    match found {
        Some(Found { line, message }) => Error::file_line(path, line, message),
        None => Error::file(path, fallback),
    }
}

fn describe_tobj_error(e: &tobj::LoadError) -> String {
    use tobj::LoadError::*;
    match e {
        FaceVertexOutOfBounds | FaceTexCoordOutOfBounds | FaceNormalOutOfBounds | FaceColorOutOfBounds => {
            "a face refers to a vertex index that does not exist (out of range or zero)".into()
        }
        PositionParseError => "a vertex line ('v') has a coordinate that is not a number".into(),
        FaceParseError => "a face line ('f') is malformed".into(),
        ReadError => "not readable as OBJ text".into(),
        other => format!("malformed OBJ: {other}"),
    }
}

/// Runs `f`, turning a panic into `None` without printing the panic message.
fn quietly_catch_unwind<R>(f: impl FnOnce() -> R + std::panic::UnwindSafe) -> Option<R> {
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let r = std::panic::catch_unwind(f).ok();
    std::panic::set_hook(hook);
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn obj(text: &[u8]) -> (tempfile::TempDir, std::path::PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.obj");
        std::fs::File::create(&p).unwrap().write_all(text).unwrap();
        (dir, p)
    }

    #[test]
    fn quads_fan_split_in_file_order() {
        let (_d, p) = obj(b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 2 3\n");
        let t = load_obj(&p).unwrap();
        assert_eq!(t.len(), 3);
        assert_eq!(t[0], [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.]]);
        assert_eq!(t[1], [[0., 0., 0.], [1., 1., 0.], [0., 1., 0.]]);
    }

    #[test]
    fn bad_inputs_are_one_line_errors() {
        let cases: &[(&[u8], &str)] = &[
            (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "out of range"),
            (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -9\n", "out of range"),
            (b"v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", "non-finite"),
            (b"v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n", "non-finite"),
            (b"v 0 0 0\n", "no faces"),
            (b"v 0 0 0\nv 1 0 0\nv 0 1 \xff\nf 1 2 3\n", "t.obj:3:7: not valid UTF-8"),
            (b"v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n", "not a number"),
        ];
        for (text, want) in cases {
            let (_d, p) = obj(text);
            let e = load_obj(&p).unwrap_err().to_string();
            assert!(e.contains(want), "{e:?} should contain {want:?}");
            assert!(e.starts_with(&p.display().to_string()));
            assert!(!e.contains('\n'));
        }
    }

    /// Comments, a blank line and valid statements ahead of every fault: seven lines, so the
    /// fault under test is on line 8 unless a case says otherwise.
    const HEAD: &str = "# written by a test\n\nv 0 0 0\nv 1 0 0\n  # indented comment\nv 0 1 0\nf 1 2 3\n";

    /// Loads `text` as `t.obj` and checks the error names `t.obj:<line>` and contains `wants`.
    fn fails_at(text: &str, line: usize, wants: &[&str]) -> String {
        let (_d, p) = obj(text.as_bytes());
        let e = load_obj(&p).unwrap_err().to_string();
        assert!(e.starts_with(&format!("{}:{line}: ", p.display())), "{e:?} should name t.obj:{line}\n{text}");
        for want in wants {
            assert!(e.contains(want), "{e:?} should contain {want:?}");
        }
        assert!(!e.contains('\n') && !e.contains('\r'), "{e:?}");
        e
    }

    #[test]
    fn vertex_line_faults_name_their_line_and_token() {
        fails_at(&format!("{HEAD}v 1 abc 0\nf 1 2 3\n"), 8, &["not a number", "'abc'"]);
        fails_at(&format!("{HEAD}v 1 2\nf 1 2 3\n"), 8, &["fewer than three"]);
        fails_at(&format!("{HEAD}v 1 2 3 w\nf 1 2 3\n"), 8, &["weight", "'w'"]);
        fails_at(&format!("{HEAD}v 1 2 3 0\nf 1 2 3\n"), 8, &["w = 0"]);
        fails_at(&format!("{HEAD}v 1 2 3 -0.0\nf 1 2 3\n"), 8, &["w = 0"]);
        fails_at(&format!("{HEAD}v 1 2 3 4 5\nf 1 2 3\n"), 8, &["5 values"]);
        fails_at(&format!("{HEAD}v 1 2 3 4 5 6 7\nf 1 2 3\n"), 8, &["7 values"]);
    }

    #[test]
    fn texcoord_normal_and_material_faults_name_their_line() {
        fails_at(&format!("{HEAD}vt 0.5\nf 1 2 3\n"), 8, &["('vt')", "two"]);
        fails_at(&format!("{HEAD}vt 0.5 q\nf 1 2 3\n"), 8, &["('vt')", "'q'"]);
        fails_at(&format!("{HEAD}vn 0 1\nf 1 2 3\n"), 8, &["('vn')", "three"]);
        fails_at(&format!("{HEAD}vn 0 1 x\nf 1 2 3\n"), 8, &["('vn')", "'x'"]);
        fails_at(&format!("{HEAD}usemtl\nf 1 2 3\n"), 8, &["usemtl", "no material"]);
    }

    #[test]
    fn malformed_faces_name_their_line_and_token() {
        fails_at(&format!("{HEAD}f 1 2 3/x\n"), 8, &["('f')", "'3/x'"]);
        fails_at(&format!("{HEAD}f 1/1/1/1 2 3\n"), 8, &["'1/1/1/1'"]);
        fails_at(&format!("{HEAD}f 1 2 3.0\n"), 8, &["'3.0'"]);
        fails_at(&format!("{HEAD}l 1 q\n"), 8, &["('l')", "'q'"]);
        // A face with no vertices at all, followed by good faces.
        fails_at(&format!("{HEAD}f\nf 1 2 3\n"), 8, &["no vertices"]);
    }

    #[test]
    fn out_of_range_indices_name_the_face_line() {
        fails_at(&format!("{HEAD}f 1 2 3\nf 1 2 9\nf 1 2 3\n"), 9, &["out of range", "'9'", "3 vertices"]);
        fails_at(&format!("{HEAD}f 1 2 -9\n"), 8, &["out of range", "'-9'"]);
        fails_at(&format!("{HEAD}f 0 1 2\n"), 8, &["out of range", "'0'", "start at 1"]);
        fails_at(&format!("{HEAD}f 1 2 /1\n"), 8, &["out of range", "'/1'"]);
        fails_at(&format!("{HEAD}l 1 2 4\n"), 8, &["out of range", "'4'"]);
        // Relative indices count back from the line they are on: -1 is the latest vertex.
        fails_at(&format!("{HEAD}f -1 -2 -3\nf -1 -2 -4\n"), 9, &["out of range", "'-4'"]);
        // A polygon's later vertices are checked too.
        fails_at(&format!("{HEAD}f 1 2 3 1 2 3 7\n"), 8, &["'7'"]);
        fails_at(&format!("{HEAD}vt 0 0\nf 1/1 2/1 3/3\n"), 9, &["texture coordinate", "'3/3'"]);
        fails_at(&format!("{HEAD}vn 0 0 1\nf 1//1 2//1 3//2\n"), 9, &["normal", "'3//2'"]);
    }

    #[test]
    fn forward_references_end_with_the_object() {
        // tobj resolves a positive index when the object ends, so a face may name a vertex
        // that comes later in the same object, but not one after the next 'o' or 'g'.
        let ok = format!("{HEAD}f 1 2 4\nv 1 1 1\n");
        let (_d, p) = obj(ok.as_bytes());
        assert_eq!(load_obj(&p).unwrap().len(), 2);
        fails_at(&format!("{HEAD}f 1 2 4\ng second\nv 1 1 1\nf 1 2 3\n"), 8, &["'4'", "line 9"]);
    }

    #[test]
    fn a_vertex_without_a_colour_among_coloured_ones_names_the_face() {
        let text = "# colours\nv 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0\nf 1 2 3\n";
        fails_at(text, 5, &["colour", "'3'"]);
    }

    #[test]
    fn non_finite_vertices_name_the_vertex_line() {
        let text = "# nan\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 0\nv 5 5 5\n\nf 1 2 3\nf 1 2 4\n";
        fails_at(text, 5, &["non-finite", "vertex 4", "line 9"]);
        fails_at(&format!("{HEAD}v 1e999 0 0\nf 1 2 4\n"), 8, &["non-finite"]);
        // Finite numbers divided by a tiny weight overflow too.
        fails_at(&format!("{HEAD}v 1e300 0 0 1e-300\nf 1 2 4\n"), 8, &["non-finite", "w"]);
        // A non-finite vertex no face uses is not part of the scene and is no error.
        let (_d, p) = obj(format!("{HEAD}v nan 0 0\n").as_bytes());
        assert_eq!(load_obj(&p).unwrap().len(), 1);
    }

    #[test]
    fn no_faces_names_the_last_line() {
        fails_at("# points only\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", 5, &["no faces"]);
        fails_at("v 0 0 0\n# no newline at the end", 2, &["no faces"]);
        fails_at("", 1, &["no faces"]);
    }

    #[test]
    fn crlf_files_count_lines_and_drop_the_cr() {
        let text = format!("{HEAD}v 1 abc 0\nf 1 2 3\n").replace('\n', "\r\n");
        fails_at(&text, 8, &["'abc'"]);
        let text = format!("{HEAD}f 1 2 3\nf 1 2 9\n").replace('\n', "\r\n");
        fails_at(&text, 9, &["'9'"]);
        let text = format!("{HEAD}usemtl \nf 1 2 3\n").replace('\n', "\r\n");
        fails_at(&text, 8, &["usemtl"]);
    }

    #[test]
    fn a_backslash_does_not_continue_a_line() {
        // tobj 4 has no line continuation: the backslash is a fourth value of its own line.
        fails_at(&format!("{HEAD}v 1 2 3 \\\n4\nf 1 2 3\n"), 8, &["weight", "'\\'"]);
    }

    // `obj_lines` finds no fault where tobj finds none (its own tests are of the faults).
    const GOOD: &str = "# fine\nv 0 0 0 1\nv 1 0 0\nvt 0 0\nvn 0 0 1\nv 0 1 0\nusemtl red\n\
                        f 1/1/1 2/1/1 3//1\ng two\nf -1 -2 -3 1\nl 1 2\nf 7\n";

    #[test]
    fn a_good_file_has_no_fault_of_any_kind() {
        assert!(tobj_load(GOOD.as_bytes()).is_ok());
        assert!(obj_lines::locate(GOOD, None).is_none());
        assert!(obj_lines::locate_non_finite(GOOD).is_none());
    }

    #[test]
    fn index_zero_of_a_texture_coordinate_means_none_to_tobj() {
        let text = "v 0 0 0\nvt 0 0\nf 1/0 1/-2 1/1\n";
        assert!(tobj_load(text.as_bytes()).is_ok());
        assert!(obj_lines::locate(text, None).is_none());
    }
}
