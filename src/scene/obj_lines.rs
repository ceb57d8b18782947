//! Finding the line of an OBJ error that tobj reported without one.
//!
//! tobj stops at the first problem and says what kind it was, not where. Loading stays one
//! pass through tobj; only when it (or one of `load_obj`'s checks) fails is the text read
//! again here, with tobj's rule for that kind of problem applied line by line, and the first
//! line that breaks the rule is the one reported. The rules are restated from tobj 4.0.5's
//! parser, for the options `load_obj` passes (triangulated, one index per vertex, points and
//! lines dropped, no material files); the tests in `obj.rs` pin each one, so a tobj upgrade
//! that changes a rule shows up there.

use std::collections::HashMap;
use std::str::SplitWhitespace;

/// A kind of fault an OBJ text can have: one per tobj error that text can cause.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Fault {
    /// 'v' with fewer than three numbers, or a coordinate or weight that is not a number.
    Position,
    /// 'v' whose weight (fourth value) is zero.
    ZeroWeight,
    /// 'v' with five, or seven or more, values.
    Colour,
    /// 'vt' without two numbers first.
    Texcoord,
    /// 'vn' without three numbers first.
    Normal,
    /// 'f' or 'l' with a vertex that is not v, v/vt, v//vn or v/vt/vn in whole numbers.
    Face,
    /// 'usemtl' without a name.
    Material,
    /// 'f' or 'l' without any vertex.
    EmptyFace,
    /// A face's vertex, texture coordinate or normal index that names nothing, or a vertex
    /// without a colour among coloured ones. tobj checks these when an object ends.
    VertexIndex,
    TexcoordIndex,
    NormalIndex,
    ColourIndex,
}

impl Fault {
    /// The fault behind a tobj error; `None` for errors no OBJ line causes (unreadable text:
    /// `load_obj` has already checked it is UTF-8).
    pub(super) fn of(e: &tobj::LoadError) -> Option<Fault> {
        use tobj::LoadError as E;
        Some(match e {
            E::PositionParseError => Fault::Position,
            E::ScalingByZeroError => Fault::ZeroWeight,
            E::ColorParseError => Fault::Colour,
            E::TexcoordParseError => Fault::Texcoord,
            E::NormalParseError => Fault::Normal,
            E::FaceParseError => Fault::Face,
            E::MaterialParseError => Fault::Material,
            E::InvalidPolygon => Fault::EmptyFace,
            E::FaceVertexOutOfBounds => Fault::VertexIndex,
            E::FaceTexCoordOutOfBounds => Fault::TexcoordIndex,
            E::FaceNormalOutOfBounds => Fault::NormalIndex,
            E::FaceColorOutOfBounds => Fault::ColourIndex,
            _ => return None,
        })
    }

    /// Faults tobj finds only when the object holding the face ends.
    fn at_object_end(self) -> bool {
        matches!(
            self,
            Fault::EmptyFace | Fault::VertexIndex | Fault::TexcoordIndex | Fault::NormalIndex | Fault::ColourIndex
        )
    }
}

/// A fault's line (numbered from 1) and what is wrong there.
#[derive(Debug)]
pub(super) struct Found {
    pub line: usize,
    pub message: String,
}

/// The number of the file's last line (1 for an empty file): where "nothing found" is reported.
pub(super) fn last_line(text: &str) -> usize {
    text.lines().count().max(1)
}

/// The first line with a fault of kind `want` (of any kind for `None`), in the order tobj meets
/// them: a line's own fault when tobj reads the line, an index fault when its object ends.
pub(super) fn locate(text: &str, want: Option<Fault>) -> Option<Found> {
    let accept = |f: Fault| want.is_none_or(|w| w == f);
    let ends = if want.is_none_or(Fault::at_object_end) { object_ends(text) } else { Vec::new() };
    let mut counts = Counts::default();
    let (mut object, mut has_faces) = (0, false);
    // The first index fault of the current object, reported when tobj would meet it.
    let mut pending = None;
    for (n, line) in numbered(text) {
        match statement(line) {
            Err((fault, message)) if accept(fault) => return Some(Found { line: n, message }),
            Err(_) => {}
            Ok(Stmt::Group) if has_faces => {
                if pending.is_some() {
                    return pending;
                }
                (object, has_faces) = (object + 1, false);
            }
            Ok(Stmt::Face { keyword, corners }) => {
                has_faces = true;
                if pending.is_none()
                    && let Some(end) = ends.get(object)
                    && let Some(message) = face_fault(keyword, corners, &counts, end, &accept)
                {
                    pending = Some(Found { line: n, message });
                }
            }
            Ok(s) => counts.add(&s),
        }
    }
    pending
}

/// The first vertex with a coordinate that is not finite (as tobj computes it: x, y, z read as
/// f64 and divided by w if given) that a face uses, faces taken in file order: the same vertex
/// `load_obj` meets first in tobj's meshes. Reported on the vertex's line.
pub(super) fn locate_non_finite(text: &str) -> Option<Found> {
    let mut bad = HashMap::new();
    let mut vertices = 0;
    for (n, line) in numbered(text) {
        match statement(line) {
            Ok(Stmt::Vertex { xyz, w, .. }) => {
                if xyz.iter().any(|c| !c.is_finite()) {
                    bad.insert(vertices, (n, xyz, w));
                }
                vertices += 1;
            }
            Err(_) => break,
            Ok(_) => {}
        }
    }
    if bad.is_empty() {
        return None;
    }
    let mut counts = Counts::default();
    for (n, line) in numbered(text) {
        match statement(line) {
            Ok(Stmt::Face { keyword, corners }) if corners.clone().count() >= 3 => {
                for word in corners {
                    let v = resolve(corner(word)?[0], counts.v);
                    if let Some(&(at, [x, y, z], w)) = bad.get(&v) {
                        let w = w.map(|w| format!(" after dividing by w = {w}")).unwrap_or_default();
                        return Some(Found {
                            line: at,
                            message: format!(
                                "vertex {} has a non-finite coordinate ({x}, {y}, {z}){w}; \
                                 {} on line {n} uses it",
                                v + 1,
                                element(keyword)
                            ),
                        });
                    }
                }
            }
            Ok(s) => counts.add(&s),
            Err(_) => return None,
        }
    }
    None
}

/// The file's lines as tobj reads them (split at `\n`, a `\r` before it dropped), numbered
/// from 1. tobj has no line continuation: a trailing `\` is an ordinary word.
fn numbered(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines().enumerate().map(|(i, l)| (i + 1, l))
}

/// What a line that tobj accepts contributes.
enum Stmt<'a> {
    /// Blank lines, comments, unknown keywords, 'mtllib', 'usemtl' with a name.
    Other,
    /// A position; `colours` is how many colour values tobj stores for it (0 to 3: it keeps
    /// those before the first that is not a number).
    Vertex {
        xyz: [f64; 3],
        w: Option<&'a str>,
        colours: usize,
    },
    Texcoord,
    Normal,
    /// 'f' or 'l' (tobj reads both alike) with its vertex words, all well formed.
    Face {
        keyword: &'a str,
        corners: SplitWhitespace<'a>,
    },
    /// 'o' or 'g': ends the current object if it has faces.
    Group,
}

/// Reads one line as tobj does, or says which of its rules the line breaks.
fn statement(line: &str) -> Result<Stmt<'_>, (Fault, String)> {
    let mut words = line.split_whitespace();
    let Some(keyword) = words.next() else { return Ok(Stmt::Other) };
    match keyword {
        "v" => vertex(words),
        "vt" => {
            numbers(words, Fault::Texcoord, "a texture coordinate line ('vt')", (2, "two")).map(|()| Stmt::Texcoord)
        }
        "vn" => numbers(words, Fault::Normal, "a normal line ('vn')", (3, "three")).map(|()| Stmt::Normal),
        "f" | "l" => {
            if let Some(bad) = words.clone().find(|w| corner(w).is_none()) {
                return Err((
                    Fault::Face,
                    format!(
                        "{} is malformed: '{bad}' is not v, v/vt, v//vn or v/vt/vn with whole-number indices",
                        element(keyword)
                    ),
                ));
            }
            Ok(Stmt::Face { keyword, corners: words })
        }
        "o" | "g" => Ok(Stmt::Group),
        // tobj takes the name after the line's first space, so `usemtl<tab>name` has none.
        "usemtl" if line.split_once(' ').is_none_or(|(_, name)| name.trim().is_empty()) => {
            Err((Fault::Material, "a 'usemtl' line names no material (the name follows the first space)".to_string()))
        }
        _ => Ok(Stmt::Other),
    }
}

fn vertex<'a>(mut words: SplitWhitespace<'a>) -> Result<Stmt<'a>, (Fault, String)> {
    let mut xyz = [0.0; 3];
    for c in &mut xyz {
        let Some(word) = words.next() else {
            return Err((Fault::Position, "a vertex line ('v') has fewer than three coordinates".to_string()));
        };
        *c = word.parse().map_err(|_| {
            (Fault::Position, format!("a vertex line ('v') has a coordinate that is not a number: '{word}'"))
        })?;
    }
    // After x y z: nothing, a weight w, or a colour r g b.
    let rest = words.clone().count();
    match rest {
        0 => Ok(Stmt::Vertex { xyz, w: None, colours: 0 }),
        1 => {
            let word = words.next().unwrap_or_default();
            let w: f64 = word.parse().map_err(|_| {
                (
                    Fault::Position,
                    format!("a vertex line ('v') has a weight (fourth value) that is not a number: '{word}'"),
                )
            })?;
            if w == 0.0 {
                return Err((
                    Fault::ZeroWeight,
                    format!("a vertex line ('v') has weight w = 0 ('{word}'); x, y and z are divided by w"),
                ));
            }
            Ok(Stmt::Vertex { xyz: xyz.map(|c| c / w), w: Some(word), colours: 0 })
        }
        3 => {
            let colours = words.take_while(|w| w.parse::<f64>().is_ok()).count();
            Ok(Stmt::Vertex { xyz, w: None, colours })
        }
        _ => Err((
            Fault::Colour,
            format!("a vertex line ('v') has {} values; it takes 3 (x y z), 4 (x y z w) or 6 (x y z r g b)", 3 + rest),
        )),
    }
}

/// Checks that `words` start with `n` numbers (tobj ignores any after them).
fn numbers(
    mut words: SplitWhitespace<'_>,
    fault: Fault,
    what: &str,
    (n, n_words): (usize, &str),
) -> Result<(), (Fault, String)> {
    for _ in 0..n {
        let Some(word) = words.next() else {
            return Err((fault, format!("{what} needs {n_words} numbers")));
        };
        if word.parse::<f64>().is_err() {
            return Err((fault, format!("{what} has a value that is not a number: '{word}'")));
        }
    }
    Ok(())
}

/// The indices of one face vertex `v`, `v/vt`, `v//vn` or `v/vt/vn`, each absent if its field
/// is empty; `None` if a field is not a whole number or there are more than three non-empty.
fn corner(word: &str) -> Option<[Option<isize>; 3]> {
    let mut parts = [None; 3];
    for (k, field) in word.split('/').enumerate() {
        if field.is_empty() {
            continue;
        }
        *parts.get_mut(k)? = Some(field.parse().ok()?);
    }
    Some(parts)
}

/// tobj's zero-based index for a field, given how many such elements precede the line.
/// Missing fields, index 0 and a relative index reaching one before the first element all
/// become `usize::MAX` (tobj's "none"); other indices before the first wrap to huge values.
fn resolve(field: Option<isize>, so_far: usize) -> usize {
    match field {
        None => usize::MAX,
        Some(i) if i < 0 => (so_far as isize + i) as usize,
        Some(i) => (i - 1) as usize,
    }
}

/// Elements read so far: positions, texture coordinates, normals, and colour values.
#[derive(Clone, Copy, Default)]
struct Counts {
    v: usize,
    vt: usize,
    vn: usize,
    colour_values: usize,
}

impl Counts {
    fn add(&mut self, s: &Stmt) {
        match s {
            Stmt::Vertex { colours, .. } => {
                self.v += 1;
                self.colour_values += colours;
            }
            Stmt::Texcoord => self.vt += 1,
            Stmt::Normal => self.vn += 1,
            Stmt::Other | Stmt::Face { .. } | Stmt::Group => {}
        }
    }
}

/// Where an object ends and what has been read by then: positive indices refer to that total.
struct End {
    counts: Counts,
    /// The 'o'/'g' line that ends it, or `None` for the end of the file.
    line: Option<usize>,
}

/// The end of every object, in order. An object ends at an 'o' or 'g' line once it has faces,
/// and at the end of the file; tobj reads no further than a line it rejects.
fn object_ends(text: &str) -> Vec<End> {
    let mut ends = Vec::new();
    let (mut counts, mut has_faces) = (Counts::default(), false);
    for (n, line) in numbered(text) {
        match statement(line) {
            Err(_) => break,
            Ok(Stmt::Group) if has_faces => {
                ends.push(End { counts, line: Some(n) });
                has_faces = false;
            }
            Ok(Stmt::Face { .. }) => has_faces = true,
            Ok(s) => counts.add(&s),
        }
    }
    ends.push(End { counts, line: None });
    ends
}

/// How messages name an 'f' or 'l' line.
fn element(keyword: &str) -> &'static str {
    if keyword == "l" { "a polyline line ('l')" } else { "a face line ('f')" }
}

/// `n` things, e.g. "1 vertex is", "3 vertices are".
fn amount(n: usize, [one, many]: [&str; 2]) -> String {
    if n == 1 { format!("1 {one} is") } else { format!("{n} {many} are") }
}

/// The first fault `accept` takes among a face's index checks, in tobj's order: vertex by
/// vertex, and for each its position, texture coordinate, normal and colour.
fn face_fault(
    keyword: &str,
    corners: SplitWhitespace<'_>,
    counts: &Counts,
    end: &End,
    accept: &impl Fn(Fault) -> bool,
) -> Option<String> {
    let size = corners.clone().count();
    if size == 0 {
        return accept(Fault::EmptyFace).then(|| format!("{} has no vertices", element(keyword)));
    }
    if size < 3 {
        return None; // a point or a line: dropped, never checked
    }
    let by = match end.line {
        Some(n) => format!("by line {n}, where the next object or group starts"),
        None => "by the end of the file".to_string(),
    };
    let t = &end.counts;
    for word in corners {
        let [v, vt, vn] = corner(word)?;
        let (iv, ivt, ivn) = (resolve(v, counts.v), resolve(vt, counts.vt), resolve(vn, counts.vn));
        let explain = |field: Option<isize>, what: [&str; 2], so_far: usize, total: usize| match field {
            None => format!("'{word}' has no {} index", what[0]),
            Some(0) => format!("'{word}' uses index 0, but OBJ indices start at 1"),
            Some(i) if i < 0 => format!(
                "'{word}' uses relative index {i}, which reaches before the first {}: only {} defined before this line",
                what[0],
                amount(so_far, what)
            ),
            Some(i) => format!("'{word}' uses {} {i}, but only {} defined {by}", what[0], amount(total, what)),
        };
        let head = format!("{} has", element(keyword));
        // A position index past the end (or "none") fails; texture coordinate and normal
        // indices are checked only if the file has any and the field names one. Indices so
        // large that tobj's multiplication wraps count as out of range here.
        if iv >= t.v {
            if accept(Fault::VertexIndex) {
                return Some(format!(
                    "{head} a vertex index out of range: {}",
                    explain(v, ["vertex", "vertices"], counts.v, t.v)
                ));
            }
            continue;
        }
        if t.vt > 0 && ivt != usize::MAX && ivt >= t.vt && accept(Fault::TexcoordIndex) {
            let e = explain(vt, ["texture coordinate", "texture coordinates"], counts.vt, t.vt);
            return Some(format!("{head} a texture coordinate index out of range: {e}"));
        }
        if t.vn > 0 && ivn != usize::MAX && ivn >= t.vn && accept(Fault::NormalIndex) {
            return Some(format!(
                "{head} a normal index out of range: {}",
                explain(vn, ["normal", "normals"], counts.vn, t.vn)
            ));
        }
        if t.colour_values > 0 && iv * 3 + 2 >= t.colour_values && accept(Fault::ColourIndex) {
            return Some(format!(
                "{head} vertex {} ('{word}'), which has no colour, while the vertex lines give colours \
                 (r g b after x y z) to the first {} only: give every vertex a colour or none",
                iv + 1,
                t.colour_values / 3
            ));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn any_fault_comes_in_tobjs_order() {
        // An index fault is met when its object ends: a bad line before that comes first.
        let text = "v 0 0 0\nf 1 1 5\nvn x\ng b\n";
        assert_eq!(locate(text, None).unwrap().line, 3);
        // After the end it comes first.
        let text = "v 0 0 0\nf 1 1 5\ng b\nvn x\n";
        let found = locate(text, None).unwrap();
        assert_eq!(found.line, 2, "{}", found.message);
        assert!(found.message.contains("by line 3"), "{}", found.message);
    }

    #[test]
    fn nothing_is_found_when_the_rule_is_not_broken() {
        // load_obj then keeps tobj's own message, without a line.
        for fault in [Fault::Position, Fault::Normal, Fault::VertexIndex, Fault::ColourIndex] {
            assert!(locate("v 0 0 0\nf 1 1 1\n", Some(fault)).is_none(), "{fault:?}");
        }
    }
}
