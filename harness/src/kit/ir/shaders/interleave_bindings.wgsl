#import gibench::interleave

// The accumulate step's bindings (Interleave::split_layout / split_group). split_position: world
// position, w = 1 where valid geometry, 0 for background or outside the image; split_normal:
// unit normal facing the camera, w = 0; split_irradiance: what the technique writes (rgb; the
// combine pass copies all four channels).
@group(0) @binding(0) var<storage, read> interleave: InterleaveParams;
@group(0) @binding(1) var<storage, read> split_position: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> split_normal: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> split_irradiance: array<vec4<f32>>;
