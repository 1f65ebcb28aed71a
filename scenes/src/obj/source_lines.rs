//! Where things are in an OBJ file. tobj returns faces without their line numbers, and forgets
//! the names of materials it could not find; warnings need both, so the text is scanned once more
//! for the few statements that matter.
//!
//! tobj reads a face from every `f` *and* `l` statement with three or more vertices (it treats
//! polylines as polygons) and drops those with one or two, in file order; this scan counts the
//! same statements, so its n-th entry is tobj's n-th face.

use std::collections::HashMap;

/// The line of one face tobj reads, whether it was written as a polyline (`l`), and the material
/// `usemtl` last selected before it (an index into [`SourceLines::materials_used`]), as written
/// whether or not a library defines it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct FaceLine {
    pub line: usize,
    pub polyline: bool,
    pub material: Option<usize>,
}

/// Lines (1-based) of the statements warnings refer to.
#[derive(Debug, Default)]
pub(crate) struct SourceLines {
    /// One entry per face tobj returns, in its order.
    pub faces: Vec<FaceLine>,
    /// The first `mtllib` line naming each library, by the name as written.
    pub libraries: HashMap<String, usize>,
    /// Every material name `usemtl` selects, with its first line, in order of first use.
    pub materials_used: Vec<(String, usize)>,
}

impl SourceLines {
    pub(super) fn scan(text: &str) -> SourceLines {
        let mut lines = SourceLines::default();
        let mut seen_materials: HashMap<&str, usize> = HashMap::new();
        let mut material = None;
        for (index, line) in text.lines().enumerate() {
            let number = index + 1;
            let mut words = line.split_whitespace();
            match words.next() {
                Some(keyword @ ("f" | "l")) if words.by_ref().count() >= 3 => {
                    lines.faces.push(FaceLine {
                        line: number,
                        polyline: keyword == "l",
                        material,
                    });
                }
                // tobj takes the rest of the line after the first space as the name.
                Some("mtllib") => {
                    let name = argument(line);
                    lines.libraries.entry(name.to_string()).or_insert(number);
                }
                Some("usemtl") => {
                    let name = argument(line);
                    // tobj refuses an empty name, so the load fails before this matters.
                    if !name.is_empty() {
                        let next = lines.materials_used.len();
                        let index = *seen_materials.entry(name).or_insert(next);
                        if index == next {
                            lines.materials_used.push((name.to_string(), number));
                        }
                        material = Some(index);
                    }
                }
                _ => {}
            }
        }
        lines
    }

    /// The line of tobj's face number `index`, when the scan agrees with tobj's count.
    pub(super) fn face(&self, index: usize) -> Option<FaceLine> {
        self.faces.get(index).copied()
    }
}

/// The argument of a statement as tobj reads it: everything after the first space, trimmed.
fn argument(line: &str) -> &str {
    line.split_once(' ').map_or("", |(_, rest)| rest.trim())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_the_statements_tobj_reads_as_faces() {
        let text = "mtllib a.mtl\nv 0 0 0\nusemtl red\nf 1 2 3\nf 1 2\nl 1 2 3 4\n  f 1 2 3 4\nusemtl red\nusemtl blue\n";
        let lines = SourceLines::scan(text);
        assert_eq!(
            lines.faces,
            vec![
                FaceLine {
                    line: 4,
                    polyline: false,
                    material: Some(0)
                },
                FaceLine {
                    line: 6,
                    polyline: true,
                    material: Some(0)
                },
                FaceLine {
                    line: 7,
                    polyline: false,
                    material: Some(0)
                },
            ]
        );
        assert_eq!(lines.libraries.get("a.mtl"), Some(&1));
        assert_eq!(
            lines.materials_used,
            vec![("red".to_string(), 3), ("blue".to_string(), 9)]
        );
    }
}
