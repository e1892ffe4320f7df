// rover's silhouette draws: every labelled thing drawn with nothing in front of it. Each
// fragment sets its pixel's bit in its entity's mask (one bit per pixel, one mask per
// entity), so overlapping parts of one thing count once and other things never hide it.

struct Globals {
    view_proj: mat4x4<f32>,
    // x: image width (px), y: mask words per entity
    size: vec4<u32>,
};

@group(0) @binding(0) var<uniform> g: Globals;
@group(0) @binding(1) var<storage, read_write> masks: array<atomic<u32>>;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) m0: vec4<f32>,
    @location(3) m1: vec4<f32>,
    @location(4) m2: vec4<f32>,
    @location(5) m3: vec4<f32>,
    @location(6) color: vec4<f32>,
    @location(7) entity: u32,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) entity: u32,
};

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    let model = mat4x4<f32>(v.m0, v.m1, v.m2, v.m3);
    var out: VertexOut;
    out.clip = g.view_proj * model * vec4<f32>(v.position, 1.0);
    out.entity = v.entity;
    return out;
}

// Drawn inside the colour pass with its targets masked off: the outputs are never written.
struct FragmentOut {
    @location(0) color: vec4<f32>,
    @location(1) entity: u32,
};

@fragment
fn fs_main(f: VertexOut) -> FragmentOut {
    let pixel = u32(f.clip.y) * g.size.x + u32(f.clip.x);
    let word = (f.entity - 1u) * g.size.y + (pixel >> 5u);
    atomicOr(&masks[word], 1u << (pixel & 31u));
    var out: FragmentOut;
    out.color = vec4<f32>(0.0);
    out.entity = 0u;
    return out;
}
