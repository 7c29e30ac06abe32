// Shared by every program (prepended first; WGSL has no include).
const PI: f32 = 3.14159265358979;
