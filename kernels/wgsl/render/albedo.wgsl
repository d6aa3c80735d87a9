// Diffuse reflectance at a surface point (CONVENTIONS.md "Materials"): a constant, a
// checkerboard, or a texture (linear RGB in `texels`, decoded from sRGB on the host),
// filtered bilinearly with texel centres at (i + 0.5) / W and repeat wrap.

// #import render/scene.wgsl

fn texture_texel(material: Material, x: i32, y: i32) -> vec3<f32> {
    let width = i32(material.texture_width);
    let height = i32(material.texture_height);
    let column = u32(((x % width) + width) % width);
    let row = u32(((y % height) + height) % height);
    return scene_texel(material.texel_offset + row * material.texture_width + column).xyz;
}

fn albedo_at(material: Material, uv: vec2<f32>) -> vec3<f32> {
    let scaled = uv * material.uv_scale;
    if material.albedo_kind == ALBEDO_CHECKERBOARD {
        let a = fract(scaled.x) > 0.5;
        let b = fract(scaled.y) > 0.5;
        return select(material.color1, material.color0, a == b);
    }
    if material.albedo_kind == ALBEDO_TEXTURE {
        let position = scaled * vec2<f32>(f32(material.texture_width), f32(material.texture_height)) - 0.5;
        let corner = floor(position);
        let f = position - corner;
        // Keep the corner in a range where i32 cannot overflow.
        let x = i32(corner.x - floor(corner.x / f32(material.texture_width)) * f32(material.texture_width));
        let y = i32(corner.y - floor(corner.y / f32(material.texture_height)) * f32(material.texture_height));
        let top = mix(texture_texel(material, x, y), texture_texel(material, x + 1, y), f.x);
        let bottom = mix(texture_texel(material, x, y + 1), texture_texel(material, x + 1, y + 1), f.x);
        return mix(top, bottom, f.y);
    }
    return material.color0;
}
