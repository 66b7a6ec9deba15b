//! Progress bars for the long phases (voxelization, light visibility,
//! rendering, saving and checking rasters): one [`ProgressBar`] is handed
//! from phase to phase, and each phase names itself, its unit and its
//! length with [`phase`]. A hidden bar ([`ProgressBar::hidden`]) costs
//! next to nothing, so the library always reports; the command line shows
//! the bar on a terminal only.

use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

/// What a phase counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    /// Objects voxelized into pieces of the raster: each object counts
    /// once per piece it reaches.
    SlabObjects,
    /// Surface voxels (records).
    Voxels,
    /// Image tiles.
    Tiles,
    /// Bytes written or read.
    Bytes,
}

impl Unit {
    fn template(self) -> &'static str {
        match self {
            Self::Bytes => {
                "{msg:26} [{bar:32}] {binary_bytes}/{binary_total_bytes} ({binary_bytes_per_sec}) {elapsed} eta {eta}"
            }
            Self::SlabObjects => {
                "{msg:26} [{bar:32}] {human_pos}/{human_len} objects×pieces {elapsed} eta {eta}"
            }
            Self::Voxels => {
                "{msg:26} [{bar:32}] {human_pos}/{human_len} voxels {elapsed} eta {eta}"
            }
            Self::Tiles => "{msg:26} [{bar:32}] {human_pos}/{human_len} tiles {elapsed} eta {eta}",
        }
    }
}

/// How often a visible bar redraws on its own, so that its elapsed time
/// and ETA move while one long step (a large object, a slow tile) runs.
const TICK: Duration = Duration::from_millis(200);

/// Starts a phase on `bar`: its message, unit and length (0: set later,
/// when known); position,
/// elapsed time and ETA from zero. The bar is redrawn at once in its new
/// style (never the previous phase's unit or length, nor indicatif's
/// default style) and then every `TICK`.
pub fn phase(bar: &ProgressBar, message: &'static str, unit: Unit, len: u64) {
    if bar.is_hidden() {
        return;
    }
    // Each change below may draw the bar: an empty line until all are
    // made, then the phase in its own style.
    if let Ok(blank) = ProgressStyle::with_template("") {
        bar.set_style(blank);
    }
    // Position, elapsed time and ETA from zero for this phase.
    bar.reset();
    if len == 0 {
        // Not known yet (a file's size): an empty bar, not a full one.
        bar.unset_length();
    } else {
        bar.set_length(len);
    }
    bar.set_message(message);
    if let Ok(style) = ProgressStyle::with_template(unit.template()) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.force_draw();
    bar.enable_steady_tick(TICK);
}

/// A phase whose length is unknown (reading a scene or a raster): a
/// spinner with the elapsed time, ticking on its own.
pub fn spinner(bar: &ProgressBar, message: String) {
    if bar.is_hidden() {
        return;
    }
    if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} {elapsed}") {
        bar.set_style(style);
    }
    bar.set_message(message);
    bar.enable_steady_tick(Duration::from_millis(120));
}
