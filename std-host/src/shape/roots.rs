//! Real roots of polynomials of degree at most 4 (the torus' quartic), by
//! recursive isolation between the roots of the derivative.

/// Up to 4 roots, unsorted.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Roots {
    r: [f64; 4],
    n: usize,
}

impl Roots {
    fn push(&mut self, x: f64) {
        if let Some(slot) = self.r.get_mut(self.n) {
            *slot = x;
            self.n += 1;
        }
    }
    pub(super) fn iter(&self) -> impl Iterator<Item = f64> + '_ {
        self.r.iter().take(self.n).copied()
    }
}

fn eval(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &a| acc * x + a)
}

/// `Σ mag_i·|x|^i`: the scale of the rounding error of `eval(c, x)` when
/// `mag` bounds the magnitudes that went into each coefficient.
fn eval_scale(mag: &[f64], x: f64) -> f64 {
    let ax = x.abs();
    mag.iter().rev().fold(0.0, |acc, &a| acc * ax + a.abs())
}

/// Real roots in `[lo, hi]` of the polynomial with ascending coefficients
/// `c` (degree ≤ 4), by recursive isolation between critical points.
/// `mag[i]` bounds the magnitudes summed into `c[i]`, for the tolerance of
/// tangent (double) roots.
pub(super) fn poly_roots(c: &[f64], mag: &[f64], lo: f64, hi: f64) -> Roots {
    let mut out = Roots::default();
    let deg = c.iter().rposition(|&a| a != 0.0).unwrap_or(0);
    let c = &c[..=deg.min(c.len().saturating_sub(1))];
    if deg == 0 {
        return out;
    }
    if deg == 1 {
        let x = -c[0] / c[1];
        if x >= lo && x <= hi {
            out.push(x);
        }
        return out;
    }
    let mut dc = [0.0; 4];
    let mut dmag = [0.0; 4];
    for (i, (a, m)) in c.iter().zip(mag).enumerate().skip(1) {
        dc[i - 1] = a * i as f64;
        dmag[i - 1] = m.abs() * i as f64;
    }
    let crit = poly_roots(&dc[..deg], &dmag[..deg], lo, hi);
    let mut pts = [0.0; 6];
    let mut n = 0;
    pts[n] = lo;
    n += 1;
    let mut cs = crit.r;
    let cs = &mut cs[..crit.n];
    cs.sort_by(f64::total_cmp);
    for &mut x in cs {
        pts[n] = x;
        n += 1;
    }
    pts[n] = hi;
    n += 1;
    let tiny = |x: f64| eval(c, x).abs() <= 1e-13 * eval_scale(mag, x);
    for w in pts[..n].windows(2) {
        let (a, b) = (w[0], w[1]);
        let (fa, fb) = (eval(c, a), eval(c, b));
        if fa == 0.0 {
            out.push(a);
        } else if (fa < 0.0) != (fb < 0.0) && fb != 0.0 {
            out.push(bisect(c, a, b, fa < 0.0));
        }
    }
    if eval(c, hi) == 0.0 {
        out.push(hi);
    }
    // Tangencies: a critical point where the polynomial (nearly) vanishes
    // without changing sign.
    for x in crit.iter() {
        if tiny(x) && out.iter().all(|r| (r - x).abs() > 1e-9 * (1.0 + x.abs())) {
            out.push(x);
        }
    }
    out
}

/// The sign change of `c` in `[a, b]`, `a_negative` telling the sign at `a`.
fn bisect(c: &[f64], mut a: f64, mut b: f64, a_negative: bool) -> f64 {
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        if (eval(c, m) < 0.0) == a_negative {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}
