//! Criterion benches: one frame of a 256 × 256-slice water grid (257² vertices) with two
//! waves and a ripple: perturbation plus analytic normals, and seed 002's face-averaged
//! normals on the same mesh. Goal: perturbation plus normals ≤ 1 ms on one core.

use criterion::{Criterion, criterion_group, criterion_main};
use water::{Grid, Perturbation, Ripple, Surface, Wave, face_averaged_normals};

fn pond_surface() -> Surface {
    let grid = Grid::try_new([-1.0, -1.0], [1.0, 1.0], [256, 256], 0.0).expect("valid grid");
    let perturbations = vec![
        Perturbation::Wave(Wave::try_new(0.004, 0.35, [1.0, 0.3], None).expect("valid")),
        Perturbation::Wave(Wave::try_new(0.002, 0.13, [-0.4, 1.0], None).expect("valid")),
        Perturbation::Ripple(
            Ripple::try_new(0.006, 0.08, [0.2, -0.1], None, [1.5, 0.3]).expect("valid"),
        ),
    ];
    Surface::new(grid, perturbations)
}

fn bench_surface(c: &mut Criterion) {
    let mut surface = pond_surface();
    let mut t = 0.0;
    c.bench_function("water_256x256_perturb_and_analytic_normals", |b| {
        b.iter(|| {
            t += 1.0 / 60.0;
            surface.evaluate(t).positions.len()
        })
    });
    let mesh = surface.evaluate(0.5).clone();
    let mut normals = Vec::new();
    c.bench_function("water_256x256_face_averaged_normals", |b| {
        b.iter(|| {
            face_averaged_normals(&mesh.positions, &mesh.triangles, &mut normals);
            normals.len()
        })
    });
}

criterion_group!(benches, bench_surface);
criterion_main!(benches);
