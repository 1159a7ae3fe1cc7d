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

/// `a` where `take_a`, else `b`, chosen by their bits: written as `if`, a choice between
/// two loads compiled to a choice of which address to load, lane by lane with branches.
#[inline(always)]
pub(super) fn pick(take_a: bool, a: f64, b: f64) -> f64 {
    let mask = u64::from(take_a).wrapping_neg();
    f64::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
}

/// The largest of `values` and 0 (NaN skipped, as `f64::max` does), in four running
/// maxima that vectorise (a maximum is exact in any order).
pub(super) fn largest(values: &[f64]) -> f64 {
    crate::avx2::with_avx2(
        #[inline(always)]
        || {
            let mut lanes = [0.0; 4];
            let quads = values.chunks_exact(4);
            let rest = quads.remainder().iter().fold(0.0, |a, &b| larger(b, a));
            for quad in quads {
                for k in 0..4 {
                    lanes[k] = larger(quad[k], lanes[k]);
                }
            }
            lanes.into_iter().fold(rest, |a, b| larger(b, a))
        },
    )
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

    #[test]
    fn largest_is_the_folded_max() {
        let values: Vec<f64> = (0..23).map(|i| ((i * 7) % 11) as f64 - 3.0).collect();
        let mut with_nan = values.clone();
        with_nan[5] = f64::NAN;
        for v in [
            &values[..],
            &with_nan[..],
            &values[..3],
            &[][..],
            &[-1.0][..],
        ] {
            assert_eq!(largest(v), v.iter().copied().fold(0.0, f64::max));
        }
    }

    #[test]
    fn pick_gives_the_chosen_bits() {
        for (a, b) in [(1.0, -2.0), (-0.0, 0.0), (f64::NAN, f64::INFINITY)] {
            assert_eq!(pick(true, a, b).to_bits(), a.to_bits());
            assert_eq!(pick(false, a, b).to_bits(), b.to_bits());
        }
    }
}
