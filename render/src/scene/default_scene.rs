//! The built-in default scene, made in code so the command line needs no file: a
//! Cornell-style room (the classic Cornell box measurements, in millimetres) with a red
//! left wall, a green right wall, two white boxes and a one-sided area light under the
//! ceiling.

use super::{Camera, Material, Scene, Shape};

type Quad = [[f32; 3]; 4];

/// Two counter-clockwise triangles of a quad given in order around its edge.
fn quad([a, b, c, d]: Quad) -> Vec<[[f32; 3]; 3]> {
    vec![[a, b, c], [a, c, d]]
}

/// The five visible faces of an upright box standing on the floor: its floor corners in
/// order (counter-clockwise seen from above) and its height.
fn upright_box(corners: [[f32; 2]; 4], height: f32) -> Vec<[[f32; 3]; 3]> {
    let low = corners.map(|[x, z]| [x, 0.0, z]);
    let high = corners.map(|[x, z]| [x, height, z]);
    let mut triangles = quad([high[0], high[3], high[2], high[1]]);
    for i in 0..4 {
        let j = (i + 1) % 4;
        triangles.extend(quad([low[i], low[j], high[j], high[i]]));
    }
    triangles
}

/// The default scene.
pub fn default_scene() -> Scene {
    let (w, h, d) = (556.0f32, 548.8f32, 559.2f32);
    let white = 0;
    let red = 1;
    let green = 2;
    let black = 3;
    let materials = vec![
        Material::diffuse([0.73, 0.73, 0.73]),
        Material::diffuse([0.65, 0.05, 0.05]),
        Material::diffuse([0.12, 0.45, 0.15]),
        Material::black(true),
    ];
    let material_names = ["white", "red", "green", "light"].map(String::from).to_vec();
    let mut shapes = Vec::new();
    let mut add = |name: &str, material: usize, emission: Option<[f32; 3]>, triangles: Vec<[[f32; 3]; 3]>| {
        let object_id = shapes.len() as u32;
        shapes.push(Shape {
            name: name.into(),
            object_id,
            material,
            emission,
            triangles,
            uvs: None,
            degenerate_dropped: 0,
        });
    };
    add("floor", white, None, quad([[0.0, 0.0, 0.0], [0.0, 0.0, d], [w, 0.0, d], [w, 0.0, 0.0]]));
    add("ceiling", white, None, quad([[0.0, h, 0.0], [w, h, 0.0], [w, h, d], [0.0, h, d]]));
    add("back", white, None, quad([[0.0, 0.0, d], [0.0, h, d], [w, h, d], [w, 0.0, d]]));
    add("left", red, None, quad([[w, 0.0, 0.0], [w, 0.0, d], [w, h, d], [w, h, 0.0]]));
    add("right", green, None, quad([[0.0, 0.0, 0.0], [0.0, h, 0.0], [0.0, h, d], [0.0, 0.0, d]]));
    add("short box", white, None, upright_box([[130.0, 65.0], [82.0, 225.0], [240.0, 272.0], [290.0, 114.0]], 165.0));
    add("tall box", white, None, upright_box([[423.0, 247.0], [265.0, 296.0], [314.0, 456.0], [472.0, 406.0]], 330.0));
    // The light faces down (its normal is −y), 1 mm below the ceiling.
    add(
        "light",
        black,
        Some([17.0, 12.0, 4.0]),
        quad([[343.0, h - 1.0, 227.0], [343.0, h - 1.0, 332.0], [213.0, h - 1.0, 332.0], [213.0, h - 1.0, 227.0]]),
    );
    Scene {
        name: "default (Cornell-style room)".into(),
        camera: Camera {
            origin: [278.0, 273.0, -800.0],
            target: [278.0, 273.0, -799.0],
            up: [0.0, 1.0, 0.0],
            fov_deg: 39.3077,
            fov_axis: "smaller".into(),
            // 128² keeps `strata compare` with no flags, the README's first command, to
            // about a minute on lavapipe; give --width/--height for more.
            width: 128,
            height: 128,
            near_clip: 10.0,
            far_clip: 2800.0,
        },
        max_depth: 8,
        rr_depth: 5,
        materials,
        material_names,
        shapes,
        textures: Vec::new(),
        environment: None,
        warnings: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::CameraFrame;
    use crate::trace_pass::build_obvhs;
    use glam::Vec3A;
    use obvhs::ray::{Ray, RayHit};

    fn normal(t: &[[f32; 3]; 3]) -> glam::Vec3 {
        let [a, b, c] = t.map(glam::Vec3::from);
        (b - a).cross(c - a).normalize()
    }

    #[test]
    fn the_room_is_lit_from_above_and_fills_the_view() {
        let scene = default_scene();
        let light = scene.shapes.iter().find(|s| s.emission.is_some()).unwrap();
        assert!(light.triangles.iter().all(|t| normal(t).y < -0.99), "the light faces down");
        let floor = &scene.shapes[0];
        assert!(floor.triangles.iter().all(|t| normal(t).y > 0.99), "the floor faces up");
        // Every camera ray away from the image border hits something (the classic framing
        // shows a sliver outside the box at the very edges).
        let (triangles, ids) = scene.triangles_with_ids();
        let (tris, bvh) = build_obvhs(&triangles);
        let frame = CameraFrame::new(&scene.camera).unwrap();
        let mut seen = std::collections::BTreeSet::new();
        for y in 2..30 {
            for x in 2..30 {
                let (origin, direction) = frame.ray((x as f32 + 0.5) / 32.0, (y as f32 + 0.5) / 32.0);
                let ray = Ray::new(Vec3A::from(origin), Vec3A::from(direction), 0.0, 1e5);
                let mut hit = RayHit::none();
                let found =
                    bvh.ray_traverse(ray, &mut hit, |r, i| tris[bvh.primitive_indices[i] as usize].intersect(r));
                assert!(found, "pixel {x},{y} sees nothing");
                seen.insert(ids[bvh.primitive_indices[hit.primitive_id as usize] as usize]);
            }
        }
        assert!(seen.len() >= 6, "the camera sees only {seen:?}");
    }
}
