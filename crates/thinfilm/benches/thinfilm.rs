//! Throughput of the optics: the f64 reference (`ThinFilm::response`, the transfer matrix)
//! and the f32 batch kernels, in (thickness, wavelength) samples per second on one core.

use criterion::{BenchmarkId, Criterion, Throughput, black_box, criterion_group, criterion_main};
use thinfilm::airy::ThinFilm;
use thinfilm::batch;
use thinfilm::dispersion::RefractiveIndex;
use thinfilm::{Layer, Stack};

/// The LUT baker's shape: one row of thicknesses, many wavelengths.
const THICKNESSES: usize = 1024;
const WAVELENGTHS: usize = 95; // 360..=830 nm every 5 nm

fn thicknesses() -> Vec<f32> {
    (0..THICKNESSES)
        .map(|i| i as f32 * 2000.0 / (THICKNESSES - 1) as f32)
        .collect()
}

fn wavelengths() -> Vec<f32> {
    (0..WAVELENGTHS).map(|k| 360.0 + 5.0 * k as f32).collect()
}

fn bench_reference(c: &mut Criterion) {
    let mut group = c.benchmark_group("f64_reference");
    let d = thicknesses();
    let l = wavelengths();
    let samples = (d.len() / 8) * l.len();
    group.throughput(Throughput::Elements(samples as u64));
    group.bench_function("ThinFilm::response", |b| {
        b.iter(|| {
            let mut sum = 0.0;
            for &d in d.iter().step_by(8) {
                let film = ThinFilm::soap(d as f64);
                for &l in &l {
                    sum += film.response(l as f64, black_box(0.8)).r();
                }
            }
            sum
        })
    });
    group.bench_function("Stack::response (TMM, one layer)", |b| {
        b.iter(|| {
            let mut sum = 0.0;
            for &d in d.iter().step_by(8) {
                let stack = ThinFilm::soap(d as f64).try_stack().unwrap();
                for &l in &l {
                    sum += stack.response(l as f64, black_box(0.8)).r();
                }
            }
            sum
        })
    });
    group.finish();
}

fn bench_batch(c: &mut Criterion) {
    let mut group = c.benchmark_group("f32_batch");
    let d = thicknesses();
    let l = wavelengths();
    let n: Vec<f32> = l
        .iter()
        .map(|&x| RefractiveIndex::Water.n_at(x as f64) as f32)
        .collect();
    let w: Vec<[f32; 3]> = l
        .iter()
        .map(|&x| [x / 830.0, 0.5, 1.0 - x / 830.0])
        .collect();
    let samples = (d.len() * l.len()) as u64;

    group.throughput(Throughput::Elements(samples));
    for cos in [1.0f32, 0.3] {
        group.bench_with_input(
            BenchmarkId::new("weighted_reflectance_row", cos),
            &cos,
            |b, &cos| {
                let mut out = vec![[0.0f32; 3]; d.len()];
                b.iter(|| {
                    batch::weighted_reflectance_row(1.0, black_box(cos), &l, &n, &w, &d, &mut out)
                })
            },
        );
    }
    group.bench_function("try_weighted_response_row (R and T)", |b| {
        let mut out_r = vec![[0.0f32; 3]; d.len()];
        let mut out_t = vec![[0.0f32; 3]; d.len()];
        b.iter(|| {
            batch::try_weighted_response_row(
                1.0,
                black_box(0.8),
                &l,
                &n,
                &w,
                &d,
                &mut out_r,
                &mut out_t,
            )
            .unwrap()
        })
    });

    let count = 4096;
    let sd: Vec<f32> = (0..count).map(|i| (i * 7919 % 2000) as f32).collect();
    let sc: Vec<f32> = (0..count)
        .map(|i| ((i * 104_729) % 1000) as f32 / 1000.0)
        .collect();
    let sl: Vec<f32> = (0..count)
        .map(|i| 360.0 + ((i * 31) % 470) as f32)
        .collect();
    group.throughput(Throughput::Elements(count as u64));
    group.bench_function("reflectance (per sample)", |b| {
        let mut out = vec![0.0f32; count];
        b.iter(|| batch::reflectance(1.0, 1.33, &sd, &sc, &sl, &mut out))
    });
    group.finish();
}

/// The 5-layer stack of `bench/vs_colour_multilayer.py` over λ 360–830 nm by 1 and angles
/// 0–75° by 7.5 (5 181 points): the transfer matrix per point against the grid.
fn bench_stack_grid(c: &mut Criterion) {
    use thinfilm::grid::Polarisation;
    use thinfilm::stack_grid::StackGrid;
    let layers = [
        (1.38, 100.0),
        (2.1, 60.0),
        (1.46, 90.0),
        (2.1, 60.0),
        (1.38, 100.0),
    ]
    .map(|(n, d)| Layer::lossless(n, d))
    .to_vec();
    let stack = Stack::new(1.0, layers, 1.52).unwrap();
    let wavelengths: Vec<f64> = (360..=830).map(f64::from).collect();
    let angles: Vec<f64> = (0..=10).map(|k| 7.5 * f64::from(k)).collect();
    let points = (wavelengths.len() * angles.len()) as u64;
    let mut group = c.benchmark_group("stack_5_layers_5181_points");
    group.throughput(Throughput::Elements(points));
    group.bench_function("transfer_matrix_per_point", |b| {
        b.iter(|| {
            let mut sum = 0.0;
            for &angle in &angles {
                let incidence = thinfilm::Incidence::try_from_angle_deg(angle).unwrap();
                for &wl in &wavelengths {
                    sum += stack.try_response_at(wl, incidence).unwrap().r();
                }
            }
            black_box(sum)
        })
    });
    let (mut r, mut t) = (vec![0.0; points as usize], vec![0.0; points as usize]);
    group.bench_function("stack_grid", |b| {
        b.iter(|| {
            let grid = StackGrid::try_new(&stack, &angles, &wavelengths).unwrap();
            grid.try_fill(Polarisation::Unpolarised, &mut r, &mut t)
                .unwrap();
            black_box(r[0])
        })
    });
    group.finish();
}

/// colour-science's film grid (d 0–2000 nm by 10, angles 0–75° by 7.5, λ 360–830 nm by 1:
/// 1 041 381 points, soap in air), one core: the exact fill against the f32 fast fill.
fn bench_film_grid(c: &mut Criterion) {
    use thinfilm::grid::{FilmGrid, Polarisation};
    let angles: Vec<f64> = (0..=10).map(|k| 7.5 * f64::from(k)).collect();
    let wavelengths: Vec<f64> = (360..=830).map(f64::from).collect();
    let thicknesses: Vec<f64> = (0..=200).map(|k| 10.0 * f64::from(k)).collect();
    let grid = FilmGrid::try_new(1.0, 1.33, &angles, &wavelengths).unwrap();
    let row = grid.len();
    let (mut r, mut t) = (
        vec![0.0; row * thicknesses.len()],
        vec![0.0; row * thicknesses.len()],
    );
    let mut group = c.benchmark_group("film_grid_1041381_points");
    group.throughput(Throughput::Elements(r.len() as u64));
    for fast in [false, true] {
        group.bench_function(if fast { "fast_f32" } else { "exact_f64" }, |b| {
            b.iter(|| {
                let rows = r.chunks_mut(row).zip(t.chunks_mut(row));
                for ((r, t), &d) in rows.zip(&thicknesses) {
                    let pol = Polarisation::Unpolarised;
                    if fast {
                        grid.try_fill_cells_fast(d, 0, pol, r, t).unwrap();
                    } else {
                        grid.try_fill(d, pol, r, t).unwrap();
                    }
                }
                black_box(r[0])
            })
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    bench_reference,
    bench_batch,
    bench_stack_grid,
    bench_film_grid
);
criterion_main!(benches);
