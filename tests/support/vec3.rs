//! Float vectors of the test-side geometry (`[f64; 3]`): the products,
//! lengths and Bézier points the property tests and the thickness bounds
//! measure the integer voxelizers against.

/// `a − b`.
#[must_use]
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|k| a[k] - b[k])
}

/// The dot product.
#[must_use]
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The cross product.
#[must_use]
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The Euclidean length.
#[must_use]
pub fn length(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// The normal of triangle `t` by its winding, twice the triangle's area
/// long.
#[must_use]
pub fn triangle_normal(t: [[f64; 3]; 3]) -> [f64; 3] {
    cross(sub(t[1], t[0]), sub(t[2], t[0]))
}

/// The point at `(u, v)` of the bicubic Bézier patch with fixed-point
/// control points `control`.
#[must_use]
pub fn bezier(control: &[[[i64; 3]; 4]; 4], u: f64, v: f64) -> [f64; 3] {
    let b = |t: f64| {
        [
            (1.0 - t).powi(3),
            3.0 * t * (1.0 - t).powi(2),
            3.0 * t * t * (1.0 - t),
            t.powi(3),
        ]
    };
    let (bu, bv) = (b(u), b(v));
    let mut out = [0.0; 3];
    for a in 0..4 {
        for c in 0..4 {
            for k in 0..3 {
                out[k] += bu[a] * bv[c] * control[a][c][k] as f64;
            }
        }
    }
    out
}
