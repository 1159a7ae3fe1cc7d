//! CIELAB and the CIEDE2000 colour difference.

/// A CIE 1976 L*a*b* colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lab {
    /// Lightness L*, 0 (black) to 100 (the reference white).
    pub l: f64,
    /// Red–green opponent coordinate a*.
    pub a: f64,
    /// Yellow–blue opponent coordinate b*.
    pub b: f64,
}

/// CIELAB of `xyz` relative to the reference white `white_xyz` (CIE 015:2018).
///
/// Only ratios `xyz / white_xyz` matter, so any common scale works.
pub fn lab_from_xyz(xyz: [f64; 3], white_xyz: [f64; 3]) -> Lab {
    let f = |t: f64| {
        // δ = 6/29: below δ³ the cube root is replaced by its tangent line.
        const DELTA: f64 = 6.0 / 29.0;
        if t > DELTA * DELTA * DELTA {
            t.cbrt()
        } else {
            t / (3.0 * DELTA * DELTA) + 4.0 / 29.0
        }
    };
    let [fx, fy, fz] = [0, 1, 2].map(|i| f(xyz[i] / white_xyz[i]));
    Lab {
        l: 116.0 * fy - 16.0,
        a: 500.0 * (fx - fy),
        b: 200.0 * (fy - fz),
    }
}

/// `√(a² + b²)`: directly for any colour (|a|, |b| < 1e150), where it is exact to an
/// ulp and several times faster than `hypot`, whose overflow guard only matters beyond.
fn chroma(a: f64, b: f64) -> f64 {
    if a.abs().max(b.abs()) < 1e150 {
        (a * a + b * b).sqrt()
    } else {
        a.hypot(b)
    }
}

/// The CIEDE2000 colour difference ΔE₀₀ (CIE 142-2001) with kL = kC = kH = 1,
/// following Sharma, Wu & Dalal (2005), including their conventions for the
/// mean hue at exactly opposite hues.
pub fn ciede2000(a: Lab, b: Lab) -> f64 {
    let c_mean_ab = 0.5 * (chroma(a.a, a.b) + chroma(b.a, b.b));
    let g = 0.5 * (1.0 - (c_mean_ab.powi(7) / (c_mean_ab.powi(7) + 25f64.powi(7))).sqrt());
    let (c1, h1) = chroma_hue(a, g);
    let (c2, h2) = chroma_hue(b, g);

    let dl = b.l - a.l;
    let dc = c2 - c1;
    let dh_deg = hue_difference_deg(c1, c2, h1, h2);
    let dh = 2.0 * (c1 * c2).sqrt() * (dh_deg.to_radians() * 0.5).sin();

    let l_mean = 0.5 * (a.l + b.l);
    let c_mean = 0.5 * (c1 + c2);
    let h_mean = hue_mean_deg(c1, c2, h1, h2);

    let t = 1.0 - 0.17 * (h_mean - 30.0).to_radians().cos()
        + 0.24 * (2.0 * h_mean).to_radians().cos()
        + 0.32 * (3.0 * h_mean + 6.0).to_radians().cos()
        - 0.20 * (4.0 * h_mean - 63.0).to_radians().cos();
    let d_theta = 30.0 * (-((h_mean - 275.0) / 25.0).powi(2)).exp();
    let r_c = 2.0 * (c_mean.powi(7) / (c_mean.powi(7) + 25f64.powi(7))).sqrt();
    let l50 = (l_mean - 50.0).powi(2);
    let s_l = 1.0 + 0.015 * l50 / (20.0 + l50).sqrt();
    let s_c = 1.0 + 0.045 * c_mean;
    let s_h = 1.0 + 0.015 * c_mean * t;
    let r_t = -(2.0 * d_theta).to_radians().sin() * r_c;

    let (tl, tc, th) = (dl / s_l, dc / s_c, dh / s_h);
    (tl * tl + tc * tc + th * th + r_t * tc * th).sqrt()
}

/// Rounding slack when deciding whether two hues are more than 180° apart:
/// hues exactly opposite must not flip with the last bit of `atan2`.
const HUE_EPS_DEG: f64 = 1e-9;

/// C′ and h′ (degrees in [0, 360)) after CIEDE2000's a* rescaling by 1 + G.
fn chroma_hue(lab: Lab, g: f64) -> (f64, f64) {
    let a = (1.0 + g) * lab.a;
    let c = chroma(a, lab.b);
    let h = if c == 0.0 {
        0.0
    } else {
        lab.b.atan2(a).to_degrees().rem_euclid(360.0)
    };
    (c, h)
}

/// Δh′ in degrees, wrapped into [−180, 180]; 0 when either chroma is 0.
fn hue_difference_deg(c1: f64, c2: f64, h1: f64, h2: f64) -> f64 {
    if c1 * c2 == 0.0 {
        return 0.0;
    }
    let d = h2 - h1;
    if d.abs() <= 180.0 + HUE_EPS_DEG {
        d
    } else if d > 0.0 {
        d - 360.0
    } else {
        d + 360.0
    }
}

/// The mean hue h̄′ in degrees; the plain sum when either chroma is 0.
fn hue_mean_deg(c1: f64, c2: f64, h1: f64, h2: f64) -> f64 {
    let sum = h1 + h2;
    if c1 * c2 == 0.0 {
        sum
    } else if (h1 - h2).abs() <= 180.0 + HUE_EPS_DEG {
        0.5 * sum
    } else if sum < 360.0 {
        0.5 * (sum + 360.0)
    } else {
        0.5 * (sum - 360.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_is_l100_and_black_is_l0() {
        let w = [0.95, 1.0, 1.09];
        let white = lab_from_xyz(w, w);
        assert!((white.l - 100.0).abs() < 1e-12 && white.a.abs() < 1e-12 && white.b.abs() < 1e-12);
        let black = lab_from_xyz([0.0; 3], w);
        assert!(black.l.abs() < 1e-12);
    }

    #[test]
    fn identical_colours_have_zero_difference() {
        let c = Lab {
            l: 40.0,
            a: 12.0,
            b: -30.0,
        };
        assert_eq!(ciede2000(c, c), 0.0);
    }
}
