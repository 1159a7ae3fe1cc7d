//! Vertex normals: analytic normals are unit length, and seed 002's face-averaged normals
//! converge to them as the grid is refined.

use proptest::prelude::*;
use water::{Grid, Perturbation, Ripple, Surface, Vec3, Wave, face_averaged_normals};

fn pond(slices: usize) -> Surface {
    let grid = Grid::try_new([-0.5, -0.5], [0.5, 0.5], [slices, slices], 0.0).unwrap();
    Surface::new(
        grid,
        vec![
            Perturbation::Wave(Wave::try_new(0.01, 0.3, [1.0, 0.4], None).unwrap()),
            Perturbation::Ripple(
                Ripple::try_new(0.004, 0.12, [0.1, 0.05], None, [2.0, 0.0]).unwrap(),
            ),
        ],
    )
}

/// Largest angle (radians) between face-averaged and analytic normals, away from the
/// rim (one-sided there) and the ripple's cone tip (no tangent plane there).
fn worst_angle(slices: usize, t_s: f64) -> f64 {
    let mut surface = pond(slices);
    let mesh = surface.evaluate(t_s).clone();
    let mut averaged = Vec::new();
    face_averaged_normals(&mesh.positions, &mesh.triangles, &mut averaged);
    let n = slices + 1;
    let mut worst = 0.0f64;
    for (k, (a, b)) in averaged.iter().zip(&mesh.normals).enumerate() {
        let (i, j) = (k % n, k / n);
        let p = mesh.positions[k];
        let near_tip = (p.x - 0.1).hypot(p.z - 0.05) < 0.03;
        if i == 0 || j == 0 || i == n - 1 || j == n - 1 || near_tip {
            continue;
        }
        worst = worst.max(a.dot(*b).clamp(-1.0, 1.0).acos() as f64);
    }
    worst
}

#[test]
fn face_averaged_normals_converge_to_analytic_ones_at_second_order() {
    let errors: Vec<f64> = [32, 64, 128, 256]
        .iter()
        .map(|&s| worst_angle(s, 0.7))
        .collect();
    for w in errors.windows(2) {
        // Halving the spacing should quarter the error (central differences); allow 3×.
        assert!(
            w[1] < w[0] / 3.0,
            "errors {errors:?} do not fall at second order"
        );
    }
    assert!(
        errors[3] < 2e-3,
        "errors {errors:?}: 256 slices still off by {} rad",
        errors[3]
    );
}

#[test]
fn a_flat_grid_has_up_normals_both_ways() {
    let grid = Grid::try_new([0.0, 0.0], [1.0, 2.0], [3, 5], 0.4).unwrap();
    let mut surface = Surface::new(grid, Vec::new());
    let mesh = surface.evaluate(1.0).clone();
    let mut averaged = Vec::new();
    face_averaged_normals(&mesh.positions, &mesh.triangles, &mut averaged);
    assert!(averaged.iter().chain(&mesh.normals).all(|n| *n == Vec3::Y));
    assert!(mesh.positions.iter().all(|p| p.y == 0.4));
    assert_eq!(mesh.triangles.len(), 2 * 3 * 5);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn analytic_and_averaged_normals_are_unit_and_point_up(
        amplitude in 0.0..0.05f64,
        wavelength in 0.05..1.0f64,
        t in 0.0..10.0f64,
    ) {
        let grid = Grid::try_new([-1.0, -1.0], [1.0, 1.0], [20, 20], 0.0).unwrap();
        let ps = vec![
            Perturbation::Wave(Wave::try_new(amplitude, wavelength, [0.3, -1.0], None).unwrap()),
            Perturbation::Ripple(Ripple::try_new(amplitude, wavelength, [0.0; 2], None, [0.5, 0.1]).unwrap()),
        ];
        let mut surface = Surface::new(grid, ps);
        let mesh = surface.evaluate(t).clone();
        let mut averaged = Vec::new();
        face_averaged_normals(&mesh.positions, &mesh.triangles, &mut averaged);
        for n in mesh.normals.iter().chain(&averaged) {
            prop_assert!((n.length() - 1.0).abs() < 1e-6, "|n| = {}", n.length());
            prop_assert!(n.y > 0.0, "normal {} points down", n);
        }
    }
}
