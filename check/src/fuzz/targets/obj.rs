//! `obj`: Wavefront OBJ with its MTL library through `load_obj_from`. An input is the OBJ
//! text, then a line `#%MTL`, then the library `fuzz.mtl` that the OBJ names (so both are
//! mutated); `tex.png` and any other `.png` resolve to a small valid texture. Structure-aware
//! mutations replace, drop or duplicate lines and insert statements with edge values
//! (`v nan 0 0`, `f 0 -9 4294967296`, `Ke 1e39 1 1`, `Ni 0`, ...).

use super::super::mutate::{FuzzRng, mutate_lines};
use super::super::{Outcome, Target, build, oracle};
use super::{count, number};
use arbitrary::Unstructured;
use rand::Rng;
use std::path::Path;
use strata_render::scene::{FileSource, MemoryFiles, load_obj_from};

/// The line between the OBJ and the MTL text of an input.
const SEPARATOR: &[u8] = b"\n#%MTL\n";

/// Statements inserted by the structure-aware mutations.
const STATEMENTS: &[&str] = &[
    "f 1 2 3",
    "f -1 -2 -3",
    "f 0 0 0",
    "f 1 2",
    "f 1/1 2/2 3/3 4/4 5/5",
    "f 1//1 2//2 3//3",
    "f 4294967296 1 2",
    "f -4294967296 1 2",
    "f 1/99 2/99 3/99",
    "v nan 0 0",
    "v inf 1 1",
    "v 1e39 0 0",
    "v 0 0",
    "vt nan 0",
    "vt 1e39 1e39",
    "vn 0 0 0",
    "o",
    "g",
    "s off",
    "l 1 2",
    "p 1",
    "usemtl missing",
    "usemtl",
    "mtllib missing.mtl",
    "mtllib fuzz.mtl fuzz.mtl",
    "mtllib ../../etc/passwd",
    "newmtl",
    "newmtl again",
    "Kd -1 0 0",
    "Kd nan 1 1",
    "Ks 1e39 1 1",
    "Ke 1e39 1 1",
    "Ke -1 -1 -1",
    "Ke 1",
    "Ni 0",
    "Ni nan",
    "Ns -1",
    "Ns inf",
    "d nan",
    "d -0.5",
    "Tr 1",
    "Pm 1",
    "Pm nan",
    "Pr inf",
    "illum 3",
    "illum 7",
    "illum 99999999999",
    "map_Kd",
    "map_Kd -s 1 1 1 other.png",
    "map_Kd missing.jpg",
];

/// The target, with its texture.
pub(super) struct Obj {
    files: MemoryFiles,
}

impl Obj {
    pub(super) fn new() -> Obj {
        let mut files = MemoryFiles::default();
        files.by_extension.insert("png".into(), build::texture_png());
        Obj { files }
    }
}

/// The files plus the MTL part of the input as every `.mtl` file (so that a renamed
/// library is still read, and the loader's notice of a missing one stays rare).
struct WithLibrary<'a> {
    library: &'a [u8],
    files: &'a MemoryFiles,
}

impl FileSource for WithLibrary<'_> {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        let library = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("mtl"));
        if library { Ok(self.library.to_vec()) } else { self.files.read(path) }
    }
}

/// The OBJ and MTL parts of an input.
fn split(input: &[u8]) -> (&[u8], &[u8]) {
    match input.windows(SEPARATOR.len()).position(|w| w == SEPARATOR) {
        Some(at) => (&input[..at], &input[at + SEPARATOR.len()..]),
        None => (input, &[]),
    }
}

/// An input of `obj` and `mtl` text.
fn join(obj: &[u8], mtl: &[u8]) -> Vec<u8> {
    [obj, SEPARATOR, mtl].concat()
}

impl Target for Obj {
    fn name(&self) -> &'static str {
        "obj"
    }

    fn seeds(&self, _shared: Option<&Path>) -> Vec<Vec<u8>> {
        let cube = "mtllib fuzz.mtl\no cube\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nusemtl wood\nf 1/1 4/4 3/3 2/2\nf 5/1/1 6/2/1 7/3/1 8/4/1\n\
usemtl lamp\ng top\nf 4 8 7\nf -6 -2 -1\ns 1\no mirror\nusemtl mirror\nf 1 2 6 5\no glass\nusemtl glass\nf 2 3 7\n\
o metal\nusemtl metal\nf 1 5 8\no plain\nusemtl missing\nf 1 3 2\nl 1 2\np 3\n";
        let library = "# materials\nnewmtl wood\nKd 0.8 0.6 0.4\nmap_Kd -s 2 2 1 tex.png\nnewmtl lamp\nKd 0 0 0\nKe 5 5 4\n\
newmtl mirror\nillum 3\nKs 0.9 0.9 0.9\nNs 200\nnewmtl glass\nillum 7\nd 0.5\nNi 1.45\nTr 0.5\nnewmtl metal\nKd 0.9 0.5 0.3\n\
Pm 1\nPr 0.4\n";
        let plain = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        vec![join(cube.as_bytes(), library.as_bytes()), join(plain.as_bytes(), b""), plain.as_bytes().to_vec()]
    }

    fn generate(&self, u: &mut Unstructured) -> arbitrary::Result<Vec<u8>> {
        let mut obj = String::from("mtllib fuzz.mtl\n");
        for _ in 0..u.int_in_range(0..=6)? {
            obj += &format!("v {} {} {}\n", number(u)?, number(u)?, number(u)?);
        }
        for _ in 0..u.int_in_range(0..=4)? {
            obj += &format!("vt {} {}\n", number(u)?, number(u)?);
        }
        for _ in 0..u.int_in_range(0..=4)? {
            match u.int_in_range(0..=3)? {
                0 => obj += &format!("usemtl m{}\n", u.int_in_range(0..=2)?),
                1 => obj += &format!("o part{}\n", u.int_in_range(0..=9)?),
                _ => {
                    let corners: Vec<String> = (0..u.int_in_range(1..=5)?)
                        .map(|_| {
                            Ok(match u.int_in_range(0..=2)? {
                                0 => count(u)?,
                                1 => format!("{}/{}", count(u)?, count(u)?),
                                _ => format!("-{}", u.int_in_range(1..=8)?),
                            })
                        })
                        .collect::<arbitrary::Result<_>>()?;
                    obj += &format!("f {}\n", corners.join(" "));
                }
            }
        }
        let mut mtl = String::new();
        for index in 0..u.int_in_range(0..=2)? {
            mtl += &format!("newmtl m{index}\n");
            for _ in 0..u.int_in_range(0..=4)? {
                let statement = *u.choose(&["Kd", "Ks", "Ke", "Ni", "Ns", "d", "Tr", "Pm", "Pr", "illum", "map_Kd"])?;
                mtl += &match statement {
                    "Kd" | "Ks" | "Ke" => format!("{statement} {} {} {}\n", number(u)?, number(u)?, number(u)?),
                    "illum" => format!("illum {}\n", count(u)?),
                    "map_Kd" => "map_Kd tex.png\n".into(),
                    _ => format!("{statement} {}\n", number(u)?),
                };
            }
        }
        Ok(join(obj.as_bytes(), mtl.as_bytes()))
    }

    fn mutate(&self, rng: &mut FuzzRng, input: &[u8]) -> Option<Vec<u8>> {
        let (obj, mtl) = split(input);
        let (mut obj, mut mtl) = (obj.to_vec(), mtl.to_vec());
        let part = if rng.random_bool(0.6) { &mut obj } else { &mut mtl };
        if rng.random_bool(0.5) {
            mutate_lines(rng, part);
        } else {
            let at = part.iter().enumerate().filter(|(_, b)| **b == b'\n').map(|(i, _)| i + 1).collect::<Vec<_>>();
            let at = if at.is_empty() { 0 } else { at[rng.random_range(0..at.len())] };
            let line = format!("{}\n", STATEMENTS[rng.random_range(0..STATEMENTS.len())]);
            part.splice(at..at, line.into_bytes());
        }
        Some(join(&obj, &mtl))
    }

    fn execute(&self, input: &[u8]) -> Outcome {
        let (obj, mtl) = split(input);
        let files = WithLibrary { library: mtl, files: &self.files };
        match load_obj_from(Path::new("scene/fuzz.obj"), obj, &files) {
            Ok(scene) => match oracle::check_scene(&scene) {
                Ok(()) => Outcome::Accepted,
                Err(problem) => Outcome::Bug(problem),
            },
            Err(error) => Outcome::Refused(error.to_string()),
        }
    }
}
