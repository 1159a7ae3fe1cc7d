//! Mesh laws: icosphere counts, exact area and volume gradients (against finite
//! differences and Euler's homogeneity theorem), and the discrete rest shape.

mod common;

use bubble_dynamics::geometry::{
    area_gradient, barycentric_vertex_areas_m2, enclosed_volume_m3, surface_area_m2,
    volume_gradient,
};
use bubble_dynamics::icosphere::{
    equilibrium_icosphere, equilibrium_residual, icosphere, triangle_count, vertex_count,
};
use bubble_dynamics::{DVec3, Topology, rest_pressure_excess_pa};
use common::{assert_abs, assert_rel};
use proptest::prelude::*;

/// A level-1 icosphere with every vertex moved by up to `jitter` (radius 1).
fn jittered(jitter: &[f64]) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mesh = icosphere(1);
    let x = mesh
        .positions
        .iter()
        .enumerate()
        .map(|(i, p)| *p + DVec3::new(jitter[3 * i], jitter[3 * i + 1], jitter[3 * i + 2]))
        .collect();
    (x, mesh.triangles)
}

fn jitter() -> impl Strategy<Value = Vec<f64>> {
    proptest::collection::vec(-0.1..0.1f64, 3 * 42)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn area_gradient_matches_central_differences(j in jitter(), vertex in 0usize..42, axis in 0usize..3) {
        let (mut x, t) = jittered(&j);
        let mut grad = vec![DVec3::ZERO; x.len()];
        area_gradient(&x, &t, &mut grad);
        let h = 1e-6;
        x[vertex][axis] += h;
        let up = surface_area_m2(&x, &t);
        x[vertex][axis] -= 2.0 * h;
        let down = surface_area_m2(&x, &t);
        assert_abs("∂A/∂x", grad[vertex][axis], (up - down) / (2.0 * h), 1e-7);
    }

    #[test]
    fn volume_gradient_matches_central_differences(j in jitter(), vertex in 0usize..42, axis in 0usize..3) {
        let (mut x, t) = jittered(&j);
        let mut grad = vec![DVec3::ZERO; x.len()];
        volume_gradient(&x, &t, &mut grad);
        let h = 1e-6;
        x[vertex][axis] += h;
        let up = enclosed_volume_m3(&x, &t);
        x[vertex][axis] -= 2.0 * h;
        let down = enclosed_volume_m3(&x, &t);
        assert_abs("∂V/∂x", grad[vertex][axis], (up - down) / (2.0 * h), 1e-8);
    }

    /// Translation invariance (Σ∇ = 0) and Euler's theorem for homogeneous functions:
    /// A has degree 2 and V degree 3 in the positions, so Σ x·∇A = 2A, Σ x·∇V = 3V.
    #[test]
    fn gradients_are_translation_invariant_and_homogeneous(j in jitter(), shift in proptest::array::uniform3(-5.0..5.0f64)) {
        let (x, t) = jittered(&j);
        let (mut ga, mut gv) = (vec![DVec3::ZERO; x.len()], vec![DVec3::ZERO; x.len()]);
        area_gradient(&x, &t, &mut ga);
        volume_gradient(&x, &t, &mut gv);
        assert_abs("|Σ∇A|", ga.iter().copied().sum::<DVec3>().length(), 0.0, 1e-12);
        assert_abs("|Σ∇V|", gv.iter().copied().sum::<DVec3>().length(), 0.0, 1e-12);
        let x_dot = |g: &[DVec3]| x.iter().zip(g).map(|(p, g)| p.dot(*g)).sum::<f64>();
        assert_rel("Σ x·∇A", x_dot(&ga), 2.0 * surface_area_m2(&x, &t), 1e-12);
        assert_rel("Σ x·∇V", x_dot(&gv), 3.0 * enclosed_volume_m3(&x, &t), 1e-12);
        let moved: Vec<DVec3> = x.iter().map(|p| *p + DVec3::from(shift)).collect();
        assert_rel("V after translation", enclosed_volume_m3(&moved, &t), enclosed_volume_m3(&x, &t), 1e-12);
    }

    #[test]
    fn barycentric_areas_partition_the_surface(j in jitter()) {
        let (x, t) = jittered(&j);
        let sum: f64 = barycentric_vertex_areas_m2(&x, &t).iter().sum();
        assert_rel("Σ vertex areas", sum, surface_area_m2(&x, &t), 1e-13);
    }
}

#[test]
fn icosphere_counts_follow_v_10_4k_plus_2_and_f_20_4k() {
    for k in 0..=5 {
        let mesh = icosphere(k);
        assert_eq!(
            mesh.positions.len(),
            10 * 4usize.pow(k) + 2,
            "vertices at level {k}"
        );
        assert_eq!(
            mesh.triangles.len(),
            20 * 4usize.pow(k),
            "triangles at level {k}"
        );
        assert_eq!(mesh.positions.len(), vertex_count(k));
        assert_eq!(mesh.triangles.len(), triangle_count(k));
        let topo = Topology::try_new(mesh.triangles.clone(), mesh.positions.len())
            .expect("closed, consistently oriented");
        // Euler characteristic of a sphere: V − E + F = 2.
        let chi =
            mesh.positions.len() as i64 - topo.edges().len() as i64 + mesh.triangles.len() as i64;
        assert_eq!(chi, 2, "Euler characteristic at level {k}");
    }
    let seed = icosphere(3);
    assert_eq!(
        (seed.positions.len(), seed.triangles.len()),
        (642, 1280),
        "seed 000's mesh"
    );
}

#[test]
fn icosphere_is_outward_oriented_and_converges_to_the_sphere() {
    let sphere = 4.0 / 3.0 * std::f64::consts::PI;
    let mut last_error = f64::INFINITY;
    for k in 0..=5 {
        let mesh = icosphere(k);
        let v = enclosed_volume_m3(&mesh.positions, &mesh.triangles);
        assert!(v > 0.0, "level {k} is inside out: V = {v}");
        let error = (sphere - v) / sphere;
        // Inscribed polyhedron: volume error shrinks ~4× per level (h²); ~3× from level 0.
        assert!(
            error > 0.0 && error < last_error / 2.5,
            "level {k}: volume error {error:.3e}, previous {last_error:.3e}"
        );
        last_error = error;
    }
}

#[test]
fn topology_rejects_open_or_inconsistent_meshes() {
    let tet = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
    assert!(
        Topology::try_new(tet.clone(), 4).is_some(),
        "a tetrahedron is closed"
    );
    assert!(
        Topology::try_new(tet[..3].to_vec(), 4).is_none(),
        "open mesh accepted"
    );
    let flipped = vec![[0, 1, 2], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
    assert!(
        Topology::try_new(flipped, 4).is_none(),
        "inconsistent orientation accepted"
    );
    assert!(
        Topology::try_new(tet, 5).is_none(),
        "unused vertex accepted"
    );
}

/// Each edge's opposite vertices complete its two faces, in the order of `Edge::faces`.
#[test]
fn opposite_vertices_complete_each_edges_faces() {
    let mesh = icosphere(2);
    let n = mesh.positions.len();
    let topology = Topology::try_new(mesh.triangles, n).expect("closed");
    for (e, opposite) in topology.edges().iter().zip(topology.opposite_vertices()) {
        for (f, k) in e.faces.iter().zip(opposite) {
            let mut corners = topology.triangles()[*f as usize];
            let mut expected = [e.vertices[0], e.vertices[1], *k];
            corners.sort_unstable();
            expected.sort_unstable();
            assert_eq!(corners, expected, "edge {:?}", e.vertices);
        }
    }
}

/// Each edge's opposite corners name, as `3·face + slot`, its opposite vertices.
#[test]
fn opposite_corners_index_the_opposite_vertices() {
    let mesh = icosphere(2);
    let n = mesh.positions.len();
    let topology = Topology::try_new(mesh.triangles, n).expect("closed");
    let corners: Vec<u32> = topology.triangles().iter().flatten().copied().collect();
    for (e, (slots, opposite)) in topology.edges().iter().zip(
        topology
            .opposite_corners()
            .iter()
            .zip(topology.opposite_vertices()),
    ) {
        for ((f, slot), k) in e.faces.iter().zip(slots).zip(opposite) {
            assert_eq!(
                slot / 3,
                *f,
                "edge {:?}: corner in the wrong face",
                e.vertices
            );
            assert_eq!(corners[*slot as usize], *k, "edge {:?}", e.vertices);
        }
    }
}

/// The rest mesh is a discrete equilibrium: one pressure balances the tension at every
/// vertex. Its radii spread shrinks ~h² and its pressure tends to Laplace's 4σ/R.
#[test]
fn equilibrium_icosphere_is_at_rest_and_tends_to_the_sphere() {
    let mut last_spread = f64::INFINITY;
    let mut last_laplace_error = f64::INFINITY;
    for k in 1..=3 {
        let mesh = equilibrium_icosphere(k);
        let residual = equilibrium_residual(&mesh.positions, &mesh.triangles);
        assert!(
            residual < 1e-6,
            "level {k}: residual force {residual:.3e} of the tension"
        );
        let v = enclosed_volume_m3(&mesh.positions, &mesh.triangles);
        let r_eq = (3.0 * v / (4.0 * std::f64::consts::PI)).cbrt();
        let radii: Vec<f64> = mesh.positions.iter().map(|p| p.length()).collect();
        let spread = radii.iter().fold(0.0f64, |m, r| m.max((r - r_eq).abs())) / r_eq;
        let a = surface_area_m2(&mesh.positions, &mesh.triangles);
        let laplace_error = rest_pressure_excess_pa(0.025, a, v) / (4.0 * 0.025 / r_eq) - 1.0;
        assert!(
            spread < last_spread / 2.0,
            "level {k}: radius spread {spread:.3e}, previous {last_spread:.3e}"
        );
        assert!(
            laplace_error > 0.0 && laplace_error < last_laplace_error / 2.5,
            "level {k}: Δp/(4σ/R) − 1 = {laplace_error:.3e}, previous {last_laplace_error:.3e}"
        );
        last_spread = spread;
        last_laplace_error = laplace_error;
    }
    assert!(
        last_spread < 4e-3,
        "level 3 radius spread {last_spread:.3e}"
    );
    assert!(
        last_laplace_error < 2e-3,
        "level 3 Laplace error {last_laplace_error:.3e}"
    );
}
