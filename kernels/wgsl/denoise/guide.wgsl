// What an engine gives the denoiser for each pixel: its G-buffer, as engines already
// keep one (SVGF, Schied et al. 2017, §3 and §4.1). The renderer writes it in
// restir/entry_guide.wgsl; an engine writes its own. 48 bytes, std430.

struct DenoiseGuide {
    // The reflectance the pixel's colour is divided by before filtering and multiplied
    // by after (SVGF §4: filtering untextured illumination keeps texture detail sharp).
    // Components at or below MIN_ALBEDO are not divided.
    albedo: vec3<f32>,
    // Linear depth of the surface the pixel sees (distance along its ray; the renderer
    // gives the path length through a mirror chain, where SVGF uses clip-space depth);
    // 0: no surface (the sky): the pixel is passed through unfiltered and never used as a
    // neighbour.
    depth: f32,
    // Unit world-space normal of that surface.
    normal: vec3<f32>,
    // Object id: a previous pixel is this surface's history only if it saw the same one.
    mesh: u32,
    // Where the surface point was in the previous frame's image minus where it is in
    // this one, in pixels (a motion vector without the camera's sub-pixel jitter).
    motion: vec2<f32>,
    _pad: vec2<u32>,
}
