//! Loading the test scenes committed under `scenes/` (JSON + PLY) and refusing bad ones
//! with errors that name the file and the field or element.

use std::path::{Path, PathBuf};
use strata_render::scene::{Material, Scene, SceneError, read_ply};

fn shared_scenes() -> PathBuf {
    strata_tests::scenes_folder()
}

#[test]
fn every_shared_scene_loads_with_object_ids_and_emitters() {
    let root = shared_scenes();
    if !root.exists() {
        panic!("{} is missing: the test scenes are part of the repository", root.display());
    }
    for (name, shapes, emitters, environment) in [
        ("cornell-box", 8, 1, false),
        ("matpreview", 3, 0, true),
        ("veach-ajar", 22, 1, false),
        ("objects-grid", 102, 1, true),
    ] {
        let scene = Scene::load(&root.join(name).join("scene.json")).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(scene.shapes.len(), shapes, "{name}");
        assert_eq!(scene.shapes.iter().filter(|s| s.emission.is_some()).count(), emitters, "{name}");
        assert_eq!(scene.environment.is_some(), environment, "{name}");
        if let Some(environment) = &scene.environment {
            assert!(environment.file.exists(), "{}", environment.file.display());
            assert!(
                environment.width > 0 && environment.texels.len() == (environment.width * environment.height) as usize
            );
        }
        for (index, shape) in scene.shapes.iter().enumerate() {
            assert_eq!(shape.object_id, index as u32);
            assert!(!shape.triangles.is_empty(), "{name}/{}", shape.name);
        }
        let (triangles, ids) = scene.triangles_with_ids();
        assert_eq!(triangles.len(), ids.len());
        assert_eq!(scene.max_depth, 8);
    }
    let veach = Scene::load(&root.join("veach-ajar/scene.json")).unwrap();
    let dropped: usize = veach.shapes.iter().map(|s| s.degenerate_dropped).sum();
    assert_eq!(dropped, 62, "the door handle's zero-area triangles are dropped and counted");
    assert!(veach.materials.iter().any(|m| matches!(m, Material::Dielectric { .. })));
    assert!(veach.materials.iter().any(|m| matches!(m, Material::RoughConductor { .. })));
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// A binary PLY of `vertices` and `faces` (the fixtures' one writer).
fn ply(vertices: &[[f32; 3]], faces: &[[i32; 3]]) -> Vec<u8> {
    strata_check::fuzz::build::ply(vertices, None, faces)
}

#[test]
fn bad_meshes_are_named() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-ply-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let good = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    assert_eq!(read_ply(&write(&dir, "good.ply", &ply(&good, &[[0, 1, 2]]))).unwrap().faces.len(), 1);
    let nan = read_ply(&write(
        &dir,
        "nan.ply",
        &ply(&[[0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2]]),
    ));
    assert!(nan.unwrap_err().to_string().contains("nan.ply: vertex 1: coordinate is not finite"));
    let range = read_ply(&write(&dir, "range.ply", &ply(&good, &[[0, 1, 7]])));
    assert!(range.unwrap_err().to_string().contains("range.ply: face 0: vertex index 7 out of range"));
    let mut truncated = ply(&good, &[[0, 1, 2]]);
    truncated.truncate(truncated.len() - 3);
    let error = read_ply(&write(&dir, "cut.ply", &truncated)).unwrap_err().to_string();
    assert!(error.contains("cut.ply: face 0: the file ends early"), "{error}");
    let ascii = read_ply(&write(&dir, "ascii.ply", b"ply\nformat ascii 1.0\nend_header\n")).unwrap_err().to_string();
    assert!(ascii.contains("format `ascii` is not supported"), "{ascii}");
    let missing = read_ply(&dir.join("missing.ply")).unwrap_err();
    assert!(matches!(missing, SceneError::Io { .. }) && missing.to_string().contains("missing.ply"));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn bad_scene_files_name_the_field() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-scene-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    write(&dir, "tri.ply", &ply(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2]]));
    write(&dir, "flat.ply", &ply(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], &[[0, 1, 2]]));
    let scene = |materials: &str, shapes: &str| {
        format!(
            r#"{{"name": "t", "camera": {{"origin": [0,0,-1], "target": [0,0,0], "up": [0,1,0], "fov_deg": 40, "fov_axis": "x",
            "width": 8, "height": 8, "near_clip": 0.01, "far_clip": 100}},
            "integrator": {{"type": "path", "max_depth": 8, "rr_depth": 5, "hide_emitters": false}},
            "materials": {materials}, "shapes": {shapes}, "environment": null}}"#
        )
    };
    let load = |name: &str, text: String| {
        Scene::load(&write(&dir, name, text.as_bytes())).map(|_| ()).unwrap_err().to_string()
    };
    let ok_materials = r#"{"white": {"type": "diffuse", "reflectance": [0.5, 0.5, 0.5], "two_sided": true}}"#;
    Scene::load(&write(
        &dir,
        "ok.json",
        scene(ok_materials, r#"[{"id": "a", "mesh": "tri.ply", "material": "white"}]"#).as_bytes(),
    ))
    .unwrap();
    let unknown = load("unknown.json", scene(r#"{"m": {"type": "velvet"}}"#, "[]"));
    assert!(unknown.contains("unknown.json: field `materials.m.type`: unknown variant `velvet`"), "{unknown}");
    let missing_material =
        load("nomat.json", scene(ok_materials, r#"[{"id": "a", "mesh": "tri.ply", "material": "gold"}]"#));
    assert!(missing_material.contains("field `shapes[0].material`: no material named `gold`"), "{missing_material}");
    let typo = load("typo.json", scene(ok_materials, r#"[{"id": "a", "mesh": "tri.ply", "materail": "white"}]"#));
    assert!(typo.contains("typo.json: field `shapes[0]") && typo.contains("materail"), "{typo}");
    let flat = load("flat.json", scene(ok_materials, r#"[{"id": "a", "mesh": "flat.ply", "material": "white"}]"#));
    assert!(flat.contains("flat.ply: faces: every triangle has zero area"), "{flat}");
    let no_mesh = load("nomesh.json", scene(ok_materials, r#"[{"id": "a", "mesh": "gone.ply", "material": "white"}]"#));
    assert!(no_mesh.contains("gone.ply"), "{no_mesh}");
    let malformed = load("bad.json", "{\"name\": ".into());
    assert!(malformed.contains("bad.json"), "{malformed}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// Environment maps and textures that cannot be used are errors naming the file and
/// what is wrong: missing, not RGB, NaN or negative radiance, a `to_world` that is not a
/// rotation, a file that is not an image.
#[test]
fn bad_environment_maps_and_textures_are_named() {
    use exr::prelude::WritableImage;
    use strata_render::rgb_image::RgbImage;
    use strata_render::scene::{Environment, Texture};
    let dir =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-bad-images-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let missing = dir.join("missing.exr");
    let error = Environment::load(&missing, 1.0, None).unwrap_err().to_string();
    assert!(error.contains("missing.exr"), "{error}");

    // Written with the exr crate: strata itself refuses to write a NaN image.
    let nan = dir.join("nan.exr");
    exr::prelude::write_rgb_file(
        &nan,
        4,
        2,
        |x, y| if (x, y) == (1, 1) { (f32::NAN, 0.0, 0.0) } else { (0.0, 0.0, 0.0) },
    )
    .unwrap();
    let error = Environment::load(&nan, 1.0, None).unwrap_err().to_string();
    assert!(error.contains("nan.exr") && error.contains("(1, 1)"), "{error}");

    let negative = dir.join("negative.exr");
    let mut image = RgbImage::new(4, 2);
    image.pixels[0] = [-1.0, 0.0, 0.0];
    image.write_exr(&negative).unwrap();
    let error = Environment::load(&negative, 1.0, None).unwrap_err().to_string();
    assert!(error.contains("negative.exr") && error.contains("non-negative"), "{error}");

    let good = dir.join("good.exr");
    RgbImage::new(4, 2).write_exr(&good).unwrap();
    let scaled = [[2.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]];
    let error = Environment::load(&good, 1.0, Some(scaled)).unwrap_err().to_string();
    assert!(error.contains("good.exr") && error.contains("not a rotation"), "{error}");
    let error = Environment::load(&good, f32::NAN, None).unwrap_err().to_string();
    assert!(error.contains("scale"), "{error}");

    let gray = dir.join("gray.exr");
    exr::prelude::Image::from_channels(
        (2, 2),
        exr::prelude::SpecificChannels::build().with_channel("Y").with_pixel_fn(|_| (0.5f32,)),
    )
    .write()
    .to_file(&gray)
    .unwrap();
    let error = Environment::load(&gray, 1.0, None).unwrap_err().to_string();
    assert!(error.contains("gray.exr") && error.contains("not an RGB image"), "{error}");

    let not_png = dir.join("texture.png");
    std::fs::write(&not_png, b"this is not a PNG").unwrap();
    let error = Texture::load(&not_png, true).unwrap_err().to_string();
    assert!(error.contains("texture.png"), "{error}");
    std::fs::remove_dir_all(&dir).ok();
}
