//! The ground plane's span kernel: lit, box-filtered checker (or solid) ground for a run of
//! pixel centres along one row, written as straight-line f32 code over small arrays so the
//! compiler can keep it in SIMD registers. Other ground materials use the scalar path.

use render_scene::camera::View;
use render_scene::ground_view::GroundView;
use render_scene::index_f32::index_f32;
use render_scene::shading::GROUND_QUARTER_OFFSET_PX;
use render_scene::{Irradiance, Light, Pattern};

use super::SPAN;

/// Whether [`ground_span`] handles this ground (solid or checker albedo, no specular lobe).
pub(crate) fn span_supported(g: &GroundView<'_>) -> bool {
    let m = &g.ground.material;
    m.specular == [0.0; 3] && matches!(m.pattern, Pattern::Solid(_) | Pattern::Checker { .. })
}

/// `x.floor()` for |x| < 2²³ without branches (callers clamp larger values first).
///
/// Adding and removing 2²³ rounds `|x|` to an integer with plain float adds, which
/// vectorise; Rust's saturating `as i32` needs per-lane fix-ups that cost more.
#[inline(always)]
fn floor_small(x: f32) -> f32 {
    const TWO_POW_23: f32 = 8_388_608.0;
    let nearest = ((x.abs() + TWO_POW_23) - TWO_POW_23).copysign(x);
    nearest - f32::from(u8::from(nearest > x))
}

/// Box-filtered checker weight, as [`render_scene::shading`]'s scalar version, clamped for range
/// (summed over a pixel's quarters as `ground_albedo_over_pixel` sums them).
#[inline(always)]
fn checker_weight(p: [f32; 2], footprint: [f32; 2]) -> f32 {
    let tri = |x: f32| (x - floor_small(x) - 0.5).abs();
    let mut i = [0.0; 2];
    for k in 0..2 {
        let w = footprint[k].min(1e6) + 1e-3;
        let x = p[k].clamp(-1e6, 1e6);
        i[k] = 2.0 * (tri((x - 0.5 * w) * 0.5) - tri((x + 0.5 * w) * 0.5)) / w;
    }
    0.5 - 0.5 * i[0] * i[1]
}

/// Ground radiance at the centres of pixels `x0 .. x0 + out.len()` of row `y` (all of whose
/// centres must see the ground: inverse depth > 0) in `view`, lit by `ambient` and
/// `lights`, written to `out`.
///
/// # Panics
/// Panics if `out.len() > SPAN`.
pub(crate) fn ground_span(
    view: &View,
    ambient: &Irradiance,
    lights: &[Light],
    g: &GroundView<'_>,
    y: usize,
    x0: usize,
    out: &mut [[f32; 3]],
) {
    let n = out.len();
    assert!(n <= SPAN, "span of {n} pixels exceeds {SPAN}");
    let cy = y as f32 + 0.5;
    let (_, ay) = view.ray_coefficients(0.0, cy);
    let sx = view.x_per_px;
    let (a, b, scale) = match g.ground.material.pattern {
        Pattern::Checker { a, b, scale_m } => (a, b, scale_m),
        Pattern::Solid(c) => (c, c, 1.0),
        Pattern::Textured { .. } => unreachable!("span_supported excludes textures"),
    };
    let inv_scale = 1.0 / scale;
    // Row constants: d(x) = d0 + x·ddx.
    let d0 = view.forward + view.up * ay + view.right * (0.5 * sx - view.tan_half_x);
    let (ddx, ddy, eye) = (g.ddx, g.ddy, view.eye);
    let mut weight = [0.0f32; SPAN];
    let mut px = [0.0f32; SPAN];
    let mut pz = [0.0f32; SPAN];
    for i in 0..n {
        let x = index_f32(x0 + i);
        let (dx, dz) = (d0.x + ddx.x * x, d0.z + ddx.z * x);
        let inv_t = (g.c + g.gx * (x + 0.5) + g.gy * cy).max(1e-30);
        let t = 1.0 / inv_t;
        px[i] = eye.x + dx * t;
        pz[i] = eye.z + dz * t;
        // ∂P/∂px = t·(∂d − d·∂d.y/d.y) with 1/d.y = t/(h − eye.y).
        let inv_dy = t * g.inv_height;
        let (kx, ky) = (ddx.y * inv_dy, ddy.y * inv_dy);
        // ∂P/∂px and ∂P/∂py in x and z, in checker cells.
        let (xx, xy) = (
            (ddx.x - dx * kx) * t * inv_scale,
            (ddy.x - dx * ky) * t * inv_scale,
        );
        let (zx, zy) = (
            (ddx.z - dz * kx) * t * inv_scale,
            (ddy.z - dz * ky) * t * inv_scale,
        );
        let f = [0.5 * (xx.abs() + xy.abs()), 0.5 * (zx.abs() + zy.abs())];
        let (cx, cz) = (px[i] * inv_scale, pz[i] * inv_scale);
        let o = GROUND_QUARTER_OFFSET_PX;
        let mut sum = 0.0;
        for (sx, sy) in [(-o, -o), (o, -o), (-o, o), (o, o)] {
            sum += checker_weight([cx + sx * xx + sy * xy, cz + sx * zx + sy * zy], f);
        }
        weight[i] = 0.25 * sum;
    }
    let mut irradiance = [[0.0f32; SPAN]; 3];
    let ambient = ambient.diffuse(g.normal);
    for (k, irr) in irradiance.iter_mut().enumerate() {
        irr[..n].fill(ambient[k]);
    }
    let height = g.ground.height_m;
    for light in lights {
        add_light(
            light,
            height,
            g.normal.y,
            &px[..n],
            &pz[..n],
            &mut irradiance,
        );
    }
    for (i, o) in out.iter_mut().enumerate() {
        let w = weight[i];
        for k in 0..3 {
            // a + (b − a)·w is exact when a = b: a solid ground in a white furnace stays white.
            o[k] = (a[k] + (b[k] - a[k]) * w) * irradiance[k][i];
        }
    }
}

/// Adds one light's `L (ρ/D)² cos θ` to each point's irradiance term.
#[inline(always)]
fn add_light(
    light: &Light,
    height: f32,
    normal_y: f32,
    px: &[f32],
    pz: &[f32],
    irr: &mut [[f32; SPAN]; 3],
) {
    let ly = light.position.y - height;
    let r2 = light.radius_m * light.radius_m;
    for i in 0..px.len() {
        let (lx, lz) = (light.position.x - px[i], light.position.z - pz[i]);
        let dist2 = lx * lx + ly * ly + lz * lz;
        let inv_dist = 1.0 / dist2.sqrt();
        let cos = (normal_y * ly * inv_dist).max(0.0);
        let solid = (r2 / dist2).min(1.0) * cos;
        for (channel, radiance) in irr.iter_mut().zip(light.radiance) {
            channel[i] += solid * radiance;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_small_matches_floor_within_its_range() {
        let mut values = vec![0.0f32, -0.0, 0.5, -0.5, 1.5, -1.5, 2.5, -2.5, 1e-30, -1e-30];
        values.extend([8_388_607.0f32, -8_388_607.0, 8_388_606.5, -8_388_606.5]);
        for k in 0..20_000 {
            let x = (k as f32 - 10_000.0) * 0.137;
            values.extend([x, x * 61.0, x.next_up(), x.next_down()]);
        }
        for x in values {
            assert_eq!(floor_small(x), x.floor(), "floor({x})");
        }
    }
}
