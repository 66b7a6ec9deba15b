//! Exact rational reference for discrete rays, written independently of
//! the stepper: it collects every voxel-boundary crossing of the clipped
//! ray, sorts them, and takes the voxel at the midpoint of each interval.
//! [`check_exact`] compares a ray's Six, TwentySix and Adaptive voxels with
//! it.

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
pub fn passage(dims: [u32; 3], origin: [i64; 3], dir: [i32; 3], segment: bool) -> Option<Passage> {
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

use rrt_core::check::check_ray;
use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
use rrt_core::raster::{Extent, Raster};

/// One ray to test.
#[derive(Clone, Copy, Debug)]
pub struct Case {
    /// Raster dimensions.
    pub dims: [u32; 3],
    /// Fixed-point origin.
    pub origin: [i64; 3],
    /// Fixed-point direction (for a segment, `end − origin`).
    pub dir: [i32; 3],
    /// A segment (`t ∈ [0, 1]`) rather than a half-line.
    pub segment: bool,
}

pub fn make_ray(c: &Case) -> Option<DiscreteRay> {
    let e = Extent::new(c.dims[0], c.dims[1], c.dims[2]).unwrap();
    if c.segment {
        let to = [0, 1, 2].map(|k| c.origin[k] + i64::from(c.dir[k]));
        DiscreteRay::segment(e, c.origin, to).unwrap()
    } else {
        DiscreteRay::new(e, c.origin, c.dir).unwrap()
    }
}

/// The voxels of `ray`, through `r` or, without a raster, through an empty one.
fn coords(
    e: Extent,
    ray: DiscreteRay,
    r: Option<&Raster<'_>>,
    mode: Connectivity,
) -> Vec<[u32; 3]> {
    match r {
        Some(r) => ray
            .voxels(r, mode)
            .unwrap()
            .map(|v| e.coord(v.index).unwrap())
            .collect(),
        None => ray.path(mode).map(|v| e.coord(v.index).unwrap()).collect(),
    }
}

/// Checks one case against the oracle and runs every invariant checker; `plane` must match `case.dims`
/// (`None`: an empty raster, walked without a plane).
#[track_caller]
pub fn check_exact(case: &Case, plane: Option<&[u8]>, label: &str) {
    let e = Extent::new(case.dims[0], case.dims[1], case.dims[2]).unwrap();
    let raster = plane.map(|p| Raster::new(e, p).unwrap());
    let r = raster.as_ref();
    let p = passage(case.dims, case.origin, case.dir, case.segment);
    let ray = make_ray(case);
    let (p, ray) = match (p, ray) {
        (None, None) => return,
        (Some(p), Some(ray)) => (p, ray),
        (p, ray) => panic!(
            "{label}: oracle passage {:?} but ray {:?} for {case:?}",
            p.is_some(),
            ray.is_some()
        ),
    };
    let to_u = |v: [i64; 3]| v.map(|x| u32::try_from(x).expect("oracle voxel inside"));
    let expect: Vec<[u32; 3]> = p.intervals.iter().map(|(v, _)| to_u(*v)).collect();
    assert_eq!(
        ray.entry_voxel(),
        expect[0],
        "{label}: entry voxel, {case:?}"
    );
    assert_eq!(
        ray.exit_voxel(),
        *expect.last().unwrap(),
        "{label}: exit voxel, {case:?}"
    );

    // Six: every interval voxel (⊇ every voxel whose interior the ray passes
    // through) in order; extra voxels only where the ray crosses an edge or
    // corner, and every voxel visited touches the ray, in parameter order.
    let six = coords(e, ray, r, Connectivity::Six);
    let mut want = expect.iter().peekable();
    let mut last_touch = p.t_in;
    for (i, v) in six.iter().enumerate() {
        let t = touch(case.origin, case.dir, &p, *v).unwrap_or_else(|| {
            panic!("{label}: six voxel #{i} {v:?} does not touch the ray, {case:?}")
        });
        assert!(
            !t.lt(last_touch),
            "{label}: six voxel #{i} {v:?} out of ray order, {case:?}"
        );
        last_touch = t;
        if want.peek() == Some(&v) {
            want.next();
        } else {
            // A tie voxel: it must touch the ray only where a crossing happens.
            assert!(
                p.intervals.iter().any(|(_, start)| start.same(t)),
                "{label}: six voxel #{i} {v:?} is neither an interval voxel nor a tie voxel, {case:?}"
            );
        }
    }
    assert!(
        want.next().is_none(),
        "{label}: six ray skipped interval voxels, {case:?}\n six={six:?}\n want={expect:?}"
    );
    assert_eq!(
        ray.crossings().map(|c| c as usize),
        p.crossings,
        "{label}: crossings, {case:?}"
    );
    assert_eq!(
        six.len(),
        1 + p.crossings.iter().sum::<usize>(),
        "{label}: six count, {case:?}"
    );

    // TwentySix: the entry voxel, then the voxel holding the ray right after
    // each driving-axis crossing.
    let mut want26 = vec![expect[0]];
    for t in &p.drive_crossings {
        let (v, _) = p
            .intervals
            .iter()
            .find(|(_, start)| start.same(*t))
            .unwrap_or_else(|| panic!("{label}: no interval after a drive crossing"));
        want26.push(to_u(*v));
    }
    assert_eq!(
        ray.driving_axis(),
        p.drive,
        "{label}: driving axis, {case:?}"
    );
    let tws = coords(e, ray, r, Connectivity::TwentySix);
    assert_eq!(tws, want26, "{label}: twenty-six voxels, {case:?}");

    // Adaptive: a subsequence of six.
    let ada = coords(e, ray, r, Connectivity::Adaptive);
    let mut it = six.iter();
    for v in &ada {
        assert!(
            it.any(|s| s == v),
            "{label}: adaptive voxel {v:?} not on the six ray in order, {case:?}"
        );
    }

    if let Some(r) = r {
        for mode in Connectivity::ALL {
            if let Err(v) = check_ray(r, &ray, mode) {
                panic!("{label}: {mode:?}: {v:?}, {case:?}");
            }
        }
    }
}
