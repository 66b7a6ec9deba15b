// The static plane the traversal firmwares (and `core/panic-never`) lay
// their rasters over, and the connectivity read from an input byte.
// Included with `include!`.

/// The raster plane.
static mut PLANE: [u8; 16384] = [0; 16384];

fn mode(b: u8) -> Connectivity {
    match b % 3 {
        0 => Connectivity::Six,
        1 => Connectivity::TwentySix,
        _ => Connectivity::Adaptive,
    }
}
