// rover's camera shader: Lambert sun + sky ambient, checkered ground, distance haze; the
// labelled-entity id of every pixel into a second target (the id pass's image).

struct Globals {
    view_proj: mat4x4<f32>,
    camera_pos: vec4<f32>,
    // xyz: direction the sunlight travels (world), w: sun intensity
    sun: vec4<f32>,
    // rgb: ambient colour, w: checker square size (m)
    ambient: vec4<f32>,
    // rgb: second ground colour
    checker: vec4<f32>,
    // rgb: sky/haze colour, w: haze distance (m)
    sky: vec4<f32>,
};

@group(0) @binding(0) var<uniform> g: Globals;
// The draw's diffuse texture; surface.x > 0.5: show it instead of the instance colour.
@group(1) @binding(0) var diffuse: texture_2d<f32>;
@group(1) @binding(1) var diffuse_sampler: sampler;
@group(1) @binding(2) var<uniform> surface: vec4<f32>;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) m0: vec4<f32>,
    @location(3) m1: vec4<f32>,
    @location(4) m2: vec4<f32>,
    @location(5) m3: vec4<f32>,
    // rgb colour; a < 0 marks the checkered ground
    @location(6) color: vec4<f32>,
    // labelled entity (0: none)
    @location(7) entity: u32,
    @location(8) uv: vec2<f32>,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec4<f32>,
    @location(3) @interpolate(flat) entity: u32,
    @location(4) uv: vec2<f32>,
};

struct FragmentOut {
    @location(0) color: vec4<f32>,
    @location(1) entity: u32,
};

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    let model = mat4x4<f32>(v.m0, v.m1, v.m2, v.m3);
    let world = model * vec4<f32>(v.position, 1.0);
    var out: VertexOut;
    out.clip = g.view_proj * world;
    out.world = world.xyz;
    out.normal = (model * vec4<f32>(v.normal, 0.0)).xyz;
    out.color = v.color;
    out.entity = v.entity;
    out.uv = v.uv;
    return out;
}

@fragment
fn fs_main(f: VertexOut) -> FragmentOut {
    let texel = textureSample(diffuse, diffuse_sampler, f.uv);
    var base = f.color.rgb;
    if (surface.x > 0.5) {
        base = texel.rgb;
    }
    if (f.color.a < 0.0) {
        let cell = floor(f.world.xy / g.ambient.w);
        let odd = (i32(cell.x) + i32(cell.y)) & 1;
        if (odd == 1) {
            base = g.checker.rgb;
        }
    }
    let n = normalize(f.normal);
    let diffuse = max(dot(n, -g.sun.xyz), 0.0) * g.sun.w;
    // Hemisphere ambient: surfaces facing up see more sky.
    let sky_amount = 0.75 + 0.25 * n.z;
    var lit = base * (g.ambient.rgb * sky_amount + vec3<f32>(diffuse));
    let dist = length(f.world - g.camera_pos.xyz);
    let haze = clamp(dist / g.sky.w, 0.0, 1.0) * 0.35;
    lit = mix(lit, g.sky.rgb, haze);
    var out: FragmentOut;
    out.color = vec4<f32>(clamp(lit, vec3<f32>(0.0), vec3<f32>(1.0)), 1.0);
    out.entity = f.entity;
    return out;
}
