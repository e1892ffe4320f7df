// rover's silhouette draws: every labelled thing drawn with nothing in front of it, into a
// layer of its own. Every output is 1; the pipeline drawing a thing lets only its layer's
// output through (the others' write masks are empty).

struct Globals {
    view_proj: mat4x4<f32>,
};

@group(0) @binding(0) var<uniform> g: Globals;

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

@vertex
fn vs_main(v: VertexIn) -> @builtin(position) vec4<f32> {
    let model = mat4x4<f32>(v.m0, v.m1, v.m2, v.m3);
    return g.view_proj * model * vec4<f32>(v.position, 1.0);
}

// One output per layer of the pass: filled in by silhouette.rs.
struct FragmentOut {
    // LAYERS
};

@fragment
fn fs_main() -> FragmentOut {
    var out: FragmentOut;
    // LAYER_VALUES
    return out;
}
