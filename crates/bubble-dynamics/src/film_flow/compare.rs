//! Minimum and maximum by one comparison each, for the film step's edge loops: `f64::min`
//! and `f64::max` also test for NaN, a dozen instructions an edge. These pick what they
//! do whenever `b` is a number, and `b` when `a` is NaN.

/// `a` where it is greater than `b`, else `b`: `a.max(b)` for a number `b`.
#[inline(always)]
pub(super) fn larger(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

/// `a` where it is less than `b`, else `b`: `a.min(b)` for a number `b`.
#[inline(always)]
pub(super) fn smaller(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn larger_and_smaller_pick_as_max_and_min_and_give_b_for_a_nan_a() {
        for (a, b) in [(1.0, 2.0), (2.0, 1.0), (-0.5, -0.5), (f64::INFINITY, 3.0)] {
            assert_eq!(larger(a, b), a.max(b), "{a}, {b}");
            assert_eq!(smaller(a, b), a.min(b), "{a}, {b}");
        }
        assert_eq!(larger(f64::NAN, 1.0), 1.0);
        assert_eq!(smaller(f64::NAN, 1.0), 1.0);
    }
}
