//! Exact parsing of the CLI's numeric arguments.
//!
//! Decimal coordinates are converted to fixed point with integer arithmetic,
//! not through `f64`, so `--origin 0.1,…` becomes exactly the fixed-point
//! value nearest to 0.1 (ties away from zero) and the first line of `rrt ray`
//! states exactly what was traced.

use rrt_core::fixed::FRAC_BITS;

/// Parses a decimal number (`[+-]digits[.digits]`, at most 30 fraction
/// digits) into fixed point with `FRAC_BITS` fractional bits, rounded to
/// nearest, ties away from zero.
///
/// # Errors
/// A message naming what is wrong with `s`.
pub fn decimal_to_fixed(s: &str) -> Result<i128, String> {
    let t = s.trim();
    let (neg, body) = match t.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, t.strip_prefix('+').unwrap_or(t)),
    };
    let (int, frac) = body.split_once('.').unwrap_or((body, ""));
    let digits_ok = |d: &str| d.bytes().all(|b| b.is_ascii_digit());
    if (int.is_empty() && frac.is_empty()) || !digits_ok(int) || !digits_ok(frac) {
        return Err(format!("expected a decimal number like 12.5, found {s:?}"));
    }
    if int.len() > 18 || frac.len() > 30 {
        return Err(format!("{s:?} has too many digits"));
    }
    let int_v: i128 = if int.is_empty() {
        0
    } else {
        int.parse().map_err(|_| format!("bad number {s:?}"))?
    };
    let frac_v: i128 = if frac.is_empty() {
        0
    } else {
        frac.parse().map_err(|_| format!("bad number {s:?}"))?
    };
    let scale = 10i128.pow(u32::try_from(frac.len()).unwrap_or(0));
    // value = int + frac/scale; fixed = round(value · 2^F).
    let num = (int_v * scale + frac_v) << FRAC_BITS;
    let q = num / scale;
    let r = num % scale;
    let mag = if 2 * r >= scale { q + 1 } else { q };
    Ok(if neg { -mag } else { mag })
}

/// Parses `A,B,C` with `one` applied to each part.
///
/// # Errors
/// A message naming the part that failed.
pub fn triple<T>(s: &str, one: impl Fn(&str) -> Result<T, String>) -> Result<[T; 3], String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected three comma-separated values, found {s:?}"
        ));
    }
    let mut out = Vec::with_capacity(3);
    for (name, p) in ["x", "y", "z"].iter().zip(&parts) {
        out.push(one(p).map_err(|e| format!("{name}: {e}"))?);
    }
    out.try_into().map_err(|_| "internal: triple".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimals_round_to_nearest_fixed() {
        assert_eq!(decimal_to_fixed("1").unwrap(), 65536);
        assert_eq!(decimal_to_fixed("-2.5").unwrap(), -163_840);
        assert_eq!(decimal_to_fixed(".5").unwrap(), 32768);
        // 0.1 · 65536 = 6553.6 → 6554
        assert_eq!(decimal_to_fixed("0.1").unwrap(), 6554);
        assert_eq!(decimal_to_fixed("-0.1").unwrap(), -6554);
        // 2^-17 exactly: a tie, away from zero.
        assert_eq!(decimal_to_fixed("0.00000762939453125").unwrap(), 1);
        for bad in ["", "-", "1.2.3", "1e5", "nan", "inf", "0x10", " 1 2", "1,5"] {
            assert!(decimal_to_fixed(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn triples_name_the_bad_part() {
        assert_eq!(
            triple("1,2,3", |s| s.parse::<u32>().map_err(|e| e.to_string())).unwrap(),
            [1, 2, 3]
        );
        let e = triple("1,x,3", |s| s.parse::<u32>().map_err(|e| e.to_string())).unwrap_err();
        assert!(e.starts_with("y:"), "{e}");
        assert!(triple("1,2", |s| s.parse::<u32>().map_err(|e| e.to_string())).is_err());
    }
}
