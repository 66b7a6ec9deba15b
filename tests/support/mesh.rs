//! Closed test meshes in fixed point: a parity inside test, boxes, and
//! OBJ meshes (read by the host's OBJ reader) fitted into a raster.

use rrt_core::fixed::VOXEL;

/// Parity inside test for a closed triangle mesh (float, test-side only).
pub fn inside_mesh(verts: &[[i64; 3]], faces: &[[u32; 3]], p: [i64; 3]) -> bool {
    let d = [0.537_7_f64, 0.314_1, 0.782_9];
    let o = p.map(|c| c as f64);
    let mut hits = 0;
    for f in faces {
        let [a, b, c] = f.map(|i| verts[i as usize].map(|x| x as f64));
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let pv = [
            d[1] * e2[2] - d[2] * e2[1],
            d[2] * e2[0] - d[0] * e2[2],
            d[0] * e2[1] - d[1] * e2[0],
        ];
        let det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
        if det.abs() < 1e-12 {
            continue;
        }
        let t = [o[0] - a[0], o[1] - a[1], o[2] - a[2]];
        let u = (t[0] * pv[0] + t[1] * pv[1] + t[2] * pv[2]) / det;
        let q = [
            t[1] * e1[2] - t[2] * e1[1],
            t[2] * e1[0] - t[0] * e1[2],
            t[0] * e1[1] - t[1] * e1[0],
        ];
        let v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
        let s = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && s > 0.0 {
            hits += 1;
        }
    }
    hits % 2 == 1
}

/// An axis-aligned box as 12 triangles.
pub fn box_mesh(lo: [i64; 3], hi: [i64; 3]) -> (Vec<[i64; 3]>, Vec<[u32; 3]>) {
    let v: Vec<[i64; 3]> = (0..8)
        .map(|i| [0, 1, 2].map(|k| if i >> k & 1 == 1 { hi[k] } else { lo[k] }))
        .collect();
    let f = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6], // z faces
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7], // y faces
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5], // x faces
    ];
    (v, f)
}

/// The OBJ mesh at `path` (read by `rrt_host::scene::obj`): its vertices
/// and triangles. Panics with the reader's message on a bad file.
#[must_use]
pub fn read_obj(path: &std::path::Path) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mesh = rrt_host::scene::obj::load(path, &path.display().to_string())
        .unwrap_or_else(|e| panic!("{e}"));
    let v = mesh.positions.iter().map(|p| p.to_array()).collect();
    (v, mesh.triangles)
}

/// Scales float vertices to fit `n − 2·margin` voxels along the longest axis.
pub fn fit(v: &[[f64; 3]], n: u32, margin: u32) -> Vec<[i64; 3]> {
    let lo = [0, 1, 2].map(|k| v.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min));
    let hi = [0, 1, 2].map(|k| v.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max));
    let size = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    let s = f64::from(n - 2 * margin) * VOXEL as f64 / size;
    v.iter()
        .map(|p| [0, 1, 2].map(|k| ((p[k] - lo[k]) * s + f64::from(margin) * VOXEL as f64) as i64))
        .collect()
}
