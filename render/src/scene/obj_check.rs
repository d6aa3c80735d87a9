//! Checks of OBJ and MTL text made before `tobj` parses it, for what `tobj` does not
//! check itself: a face index of 0 or beyond the vertices, texture coordinates or normals
//! that exist (`tobj` computes `index × 3` unchecked, which overflows on huge indices), and a
//! colour statement (`Ka`, `Kd`, `Ks`, `Ke`) with fewer than three numbers (`tobj` unwraps
//! it). Each is an error naming the line. Also found here, for warnings naming the line:
//! faces of fewer than three vertices and the `usemtl` statements.

/// The first face (or line, or point) of `text` with a vertex, texture or normal index
/// that is 0 or lies outside the elements declared so far (relative, negative indices)
/// or in the whole file (absolute ones): its line number and what is wrong.
pub(super) fn bad_face_index(text: &str) -> Option<(usize, String)> {
    let mut totals = [0i64; 3];
    for line in text.lines() {
        match line.split_whitespace().next() {
            Some("v") => totals[0] += 1,
            Some("vt") => totals[1] += 1,
            Some("vn") => totals[2] += 1,
            _ => {}
        }
    }
    let mut counts = [0i64; 3];
    for (number, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => counts[0] += 1,
            Some("vt") => counts[1] += 1,
            Some("vn") => counts[2] += 1,
            Some("f" | "l" | "p") => {
                for corner in words {
                    for (kind, index) in corner.split('/').enumerate().take(3) {
                        // Not a number: tobj refuses the line itself.
                        let Ok(index) = index.parse::<i64>() else { continue };
                        let what = ["vertex", "texture coordinate", "normal"][kind];
                        let valid =
                            if index < 0 { index >= -counts[kind] } else { index >= 1 && index <= totals[kind] };
                        if !valid {
                            return Some((
                                number + 1,
                                format!(
                                    "{what} index {index} out of range ({} declared before the line, {} in the file)",
                                    counts[kind], totals[kind]
                                ),
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    None
}

/// The lines (1-based) of faces with fewer than three vertices: not surfaces, which
/// `tobj` drops without a word.
pub(super) fn short_faces(text: &str) -> Vec<usize> {
    text.lines()
        .enumerate()
        .filter(|(_, line)| {
            let mut words = line.split_whitespace();
            words.next() == Some("f") && words.count() < 3
        })
        .map(|(number, _)| number + 1)
        .collect()
}

/// A statement about materials, in file order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) enum MaterialStatement {
    /// `mtllib FILE`: the library's file name as written.
    Library(String),
    /// `usemtl NAME`.
    Use(String),
}

/// Every `mtllib` and `usemtl` statement: its line (1-based) and what it names, read
/// as `tobj` reads them once [`prepared_for_tobj`] is applied (the name is everything
/// after the first space, trimmed).
pub(super) fn material_statements(text: &str) -> Vec<(usize, MaterialStatement)> {
    text.lines()
        .enumerate()
        .filter_map(|(number, line)| {
            let line = line.trim_start();
            let (keyword, rest) = line.split_once(' ').unwrap_or((line, ""));
            let name = rest.trim().to_string();
            match keyword {
                "mtllib" => Some((number + 1, MaterialStatement::Library(name))),
                "usemtl" => Some((number + 1, MaterialStatement::Use(name))),
                _ => None,
            }
        })
        .collect()
}

/// `text` as `tobj` should read it: every line's leading white space removed (`tobj`
/// finds a statement's keyword past indentation but reads its argument from the untrimmed
/// line, so an indented `usemtl red` would name the material "usemtl red"), and a face
/// without any vertex emptied (`tobj` refuses the whole file for it, "invalid polygon",
/// where it drops shorter faces; [`short_faces`] warns of both). Lines keep their numbers.
pub(super) fn prepared_for_tobj(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.split_inclusive('\n') {
        let unindented = line.trim_start_matches([' ', '\t']);
        if unindented.split_whitespace().eq(["f"]) {
            out.push_str(&line[line.trim_end_matches(['\r', '\n']).len()..]);
        } else {
            out.push_str(unindented);
        }
    }
    out
}

/// One warning for many lines: `line N` or `line N (and M more)`.
pub(super) fn lines_text(lines: &[usize]) -> String {
    match lines {
        [] => String::new(),
        [line] => format!("line {line}"),
        [line, rest @ ..] => format!("line {line} (and {} more)", rest.len()),
    }
}

/// The first colour statement of the MTL `text` with fewer than three numbers: its line
/// number and statement.
pub(super) fn short_colour(text: &str) -> Option<(usize, String)> {
    text.lines().enumerate().find_map(|(number, line)| {
        let mut words = line.split_whitespace();
        let statement = words.next()?;
        (["Ka", "Kd", "Ks", "Ke"].contains(&statement) && words.count() < 3)
            .then(|| (number + 1, format!("`{}` needs three numbers (r g b)", line.trim())))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_beyond_their_elements_and_short_colours_are_found() {
        let good = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 -1/-1\n";
        assert_eq!(bad_face_index(good), None);
        assert_eq!(bad_face_index("v 0 0 0\nf 1 2 0\n").unwrap().0, 2);
        assert!(bad_face_index("v 0 0 0\nf -2 1 1\n").unwrap().1.contains("vertex index -2"));
        assert!(bad_face_index("v 0 0 0\nf 1/9223372036854775807 1 1\n").unwrap().1.contains("texture coordinate"));
        assert!(bad_face_index("f -1 1 1\nv 0 0 0\n").is_some(), "relative to what is declared before");
        assert_eq!(short_colour("newmtl a\nKd 1 1 1\n"), None);
        assert_eq!(short_colour("newmtl a\nKe 1\n").unwrap().0, 2);
        assert_eq!(short_faces("v 0 0 0\nf 1 1\nf 1 1 1\nf 1\n"), [2, 4]);
        assert_eq!(
            material_statements("usemtl a b\nusemtlx\n  usemtl c\nmtllib x y.mtl\n"),
            [
                (1, MaterialStatement::Use("a b".into())),
                (3, MaterialStatement::Use("c".into())),
                (4, MaterialStatement::Library("x y.mtl".into()))
            ]
        );
        assert_eq!(prepared_for_tobj("  usemtl c\n\tf 1 2 3\nv 1 2 3"), "usemtl c\nf 1 2 3\nv 1 2 3");
        assert_eq!(prepared_for_tobj("v 1 2 3\n  f \r\nf\nf 1 1 1"), "v 1 2 3\n\r\n\nf 1 1 1");
        assert_eq!(lines_text(&[4, 9, 12]), "line 4 (and 2 more)");
    }
}
