//! Reading OBJ files through tobj, with the checks tobj does not make itself.
//!
//! Triangles are numbered in file order; tobj fan-splits a polygon v0,v1,v2,… into
//! (v0,vi,vi+1). These numbers are the ones every `--ids` output reports.

use super::Tri;
use crate::error::{Error, Result};
use std::path::Path;

/// Loads every face of `path` as world-space triangles in file order.
pub fn load_obj(path: &Path) -> Result<Vec<Tri>> {
    let bytes = std::fs::read(path).map_err(|e| Error::file(path, format!("cannot read: {e}")))?;
    if let Err(e) = std::str::from_utf8(&bytes) {
        let line = 1 + bytes[..e.valid_up_to()].iter().filter(|&&b| b == b'\n').count();
        return Err(Error::file(path, format!("line {line}: not valid UTF-8 text")));
    }
    let options = tobj::LoadOptions { triangulate: true, single_index: true, ignore_points: true, ignore_lines: true };
    // tobj reports malformed input as errors, but we do not let a parser panic take the
    // process down either: a panic here becomes the same one-line error.
    let loaded = quietly_catch_unwind(|| {
        tobj::load_obj_buf(&mut bytes.as_slice(), &options, |_| Err(tobj::LoadError::OpenFileFailed))
    });
    let (models, _materials) = match loaded {
        Some(Ok(x)) => x,
        Some(Err(e)) => return Err(Error::file(path, describe_tobj_error(&e))),
        None => return Err(Error::file(path, "malformed OBJ (the parser gave up)")),
    };
    let mut tris = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let pos = &mesh.positions;
        for (i, c) in pos.chunks(3).enumerate() {
            if c.iter().any(|x| !x.is_finite()) {
                return Err(Error::file(
                    path,
                    format!(
                        "vertex {} of object '{}' has a non-finite coordinate ({}, {}, {})",
                        i + 1,
                        model.name,
                        c[0],
                        c[1],
                        c[2]
                    ),
                ));
            }
        }
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
        return Err(Error::file(path, "no faces: the scene has no triangles"));
    }
    Ok(tris)
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
            (b"v 0 0 0\nv 1 0 0\nv 0 1 \xff\nf 1 2 3\n", "line 3: not valid UTF-8"),
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
}
