//! Support code for the integration tests in `tests/`: a seeded RNG, an
//! exact rational oracle for discrete rays, and the location of the shared
//! data folder.

use std::path::PathBuf;

/// SplitMix64: small, seedable, good enough to generate test rays.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator seeded with `seed` (each test iteration seeds its own, so
    /// any failure can be replayed from the seed printed with it).
    #[must_use]
    pub const fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }

    /// Uniform in `lo..=hi`.
    pub fn range_i64(&mut self, lo: i64, hi: i64) -> i64 {
        let span = (hi as i128 - lo as i128 + 1) as u128;
        (lo as i128 + (u128::from(self.next_u64()) % span) as i128) as i64
    }

    /// True with probability `p_num / p_den`.
    pub fn chance(&mut self, p_num: u64, p_den: u64) -> bool {
        self.below(p_den) < p_num
    }
}

/// `../shared/data` beside the repository, if present.
#[must_use]
pub fn shared_data() -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/data");
    p.is_dir().then_some(p)
}

pub mod oracle {
    //! Exact rational reference for discrete rays, written independently of
    //! the stepper: it collects every voxel-boundary crossing of the clipped
    //! ray, sorts them, and takes the voxel at the midpoint of each interval.

    use rrt_core::fixed::VOXEL;

    /// `n / d` with `d > 0`, exact in i128.
    #[derive(Clone, Copy, Debug)]
    pub struct Q {
        pub n: i128,
        pub d: i128,
    }

    impl Q {
        pub fn new(n: i128, d: i128) -> Self {
            assert!(d != 0);
            if d < 0 {
                Self { n: -n, d: -d }
            } else {
                Self { n, d }
            }
        }
        pub fn order(self, o: Self) -> std::cmp::Ordering {
            (self.n.checked_mul(o.d).unwrap()).cmp(&o.n.checked_mul(self.d).unwrap())
        }
        pub fn lt(self, o: Self) -> bool {
            self.order(o).is_lt()
        }
        pub fn same(self, o: Self) -> bool {
            self.order(o).is_eq()
        }
        /// The midpoint of two parameters.
        pub fn mid(self, o: Self) -> Self {
            let n = self
                .n
                .checked_mul(o.d)
                .unwrap()
                .checked_add(o.n.checked_mul(self.d).unwrap())
                .unwrap();
            Self::new(n, self.d.checked_mul(o.d).unwrap().checked_mul(2).unwrap())
        }
    }

    /// floor(n / d) for d > 0.
    fn floor_div(n: i128, d: i128) -> i128 {
        n.div_euclid(d)
    }

    /// The exact description of a ray's passage through a raster.
    #[derive(Debug)]
    pub struct Passage {
        /// Entry and exit parameters (`None` when the ray misses).
        pub t_in: Q,
        pub t_out: Option<Q>,
        /// Voxels holding the ray on each open interval between consecutive
        /// crossings, in order, and the parameter where each interval starts.
        pub intervals: Vec<([i64; 3], Q)>,
        /// Whether the ray lies in a voxel face (then no voxel interior is
        /// passed; the intervals use the half-open convention instead).
        pub in_face: bool,
        /// Parameters of the driving-axis crossings.
        pub drive_crossings: Vec<Q>,
        /// Number of boundary crossings strictly between entry and exit, per axis.
        pub crossings: [usize; 3],
        pub drive: usize,
    }

    /// Computes the passage of `origin + t·dir` (`t ∈ [0, 1]` for a segment,
    /// `t ≥ 0` otherwise) through a raster of `dims`. `None` if it passes
    /// through no voxel.
    pub fn passage(
        dims: [u32; 3],
        origin: [i64; 3],
        dir: [i32; 3],
        segment: bool,
    ) -> Option<Passage> {
        let s = i128::from(VOXEL);
        let size = dims.map(|n| i128::from(n) * s);
        let o = origin.map(i128::from);
        let d = dir.map(i128::from);
        let mut lo = Q::new(0, 1);
        let mut hi: Option<Q> = segment.then(|| Q::new(1, 1));
        for k in 0..3 {
            if d[k] == 0 {
                if o[k] < 0 || o[k] >= size[k] {
                    return None;
                }
                continue;
            }
            let a = Q::new(-o[k], d[k]);
            let b = Q::new(size[k] - o[k], d[k]);
            let (a, b) = if a.lt(b) { (a, b) } else { (b, a) };
            if lo.lt(a) {
                lo = a;
            }
            if hi.is_none_or(|h| b.lt(h)) {
                hi = Some(b);
            }
        }
        if let Some(h) = hi
            && !lo.lt(h)
        {
            return None;
        }
        let ad = d.map(i128::abs);
        let drive = if ad[1] > ad[0] {
            if ad[2] > ad[1] { 2 } else { 1 }
        } else if ad[2] > ad[0] {
            2
        } else {
            0
        };
        let mut cross: Vec<(Q, usize)> = Vec::new();
        if let Some(h) = hi {
            for k in 0..3 {
                if d[k] == 0 {
                    continue;
                }
                // Boundaries m·S with lo < t < h.
                let p0 = o[k] * lo.d + lo.n * d[k]; // position·lo.d
                let p1 = o[k] * h.d + h.n * d[k];
                let (a, ad_) = (p0, lo.d);
                let (b, bd) = (p1, h.d);
                let (mn, mx) = if d[k] > 0 {
                    ((a, ad_), (b, bd))
                } else {
                    ((b, bd), (a, ad_))
                };
                let m_lo = floor_div(mn.0, mn.1 * s) - 1;
                let m_hi = floor_div(mx.0, mx.1 * s) + 1;
                for m in m_lo..=m_hi {
                    let t = Q::new(m * s - o[k], d[k]);
                    if lo.lt(t) && t.lt(h) {
                        cross.push((t, k));
                    }
                }
            }
        }
        cross.sort_by(|a, b| a.0.order(b.0));
        let drive_crossings: Vec<Q> = cross.iter().filter(|c| c.1 == drive).map(|c| c.0).collect();
        let crossings = [0, 1, 2].map(|k| cross.iter().filter(|c| c.1 == k).count());
        let mut times: Vec<Q> = Vec::new();
        for (t, _) in &cross {
            if times.last().is_none_or(|l: &Q| !l.same(*t)) {
                times.push(*t);
            }
        }
        let voxel_at = |t: Q| -> [i64; 3] {
            let mut v = [0i64; 3];
            for k in 0..3 {
                let num = o[k] * t.d + t.n * d[k];
                v[k] = floor_div(num, t.d * s) as i64;
            }
            v
        };
        let mut intervals = Vec::new();
        let mut start = lo;
        for t in times
            .iter()
            .copied()
            .chain(std::iter::once(hi.unwrap_or(Q::new(lo.n + lo.d, lo.d))))
        {
            intervals.push((voxel_at(start.mid(t)), start));
            start = t;
        }
        let in_face = (0..3).any(|k| d[k] == 0 && o[k].rem_euclid(s) == 0);
        Some(Passage {
            t_in: lo,
            t_out: hi,
            intervals,
            in_face,
            drive_crossings,
            crossings,
            drive,
        })
    }

    /// The earliest parameter at which the ray touches the closed voxel `v`
    /// within `[t_in, t_out]`, or `None` if it does not touch it.
    pub fn touch(origin: [i64; 3], dir: [i32; 3], p: &Passage, v: [u32; 3]) -> Option<Q> {
        let s = i128::from(VOXEL);
        let mut lo = p.t_in;
        let mut hi = p.t_out;
        for k in 0..3 {
            let o = i128::from(origin[k]);
            let d = i128::from(dir[k]);
            let a = i128::from(v[k]) * s;
            let b = a + s;
            if d == 0 {
                if o < a || o > b {
                    return None;
                }
                continue;
            }
            let ta = Q::new(a - o, d);
            let tb = Q::new(b - o, d);
            let (ta, tb) = if ta.lt(tb) { (ta, tb) } else { (tb, ta) };
            if lo.lt(ta) {
                lo = ta;
            }
            if hi.is_none_or(|h| tb.lt(h)) {
                hi = Some(tb);
            }
        }
        match hi {
            Some(h) if h.lt(lo) => None,
            _ => Some(lo),
        }
    }
}
