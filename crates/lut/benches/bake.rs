//! Bake speed. The goal: 512 × 512 at a 5 nm step in ≤ 50 ms on 2 cores.
//!
//! `cargo bench -p lut -- --warm-up-time 1 --measurement-time 3`; divide the time by the
//! printed spectral-sample count for ns per sample.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use lut::{BakeConfig, Light};
use thinfilm::illuminant::Illuminant;

fn configs() -> Vec<(&'static str, BakeConfig)> {
    let no_lights = |w, h| {
        BakeConfig::builder()
            .resolution(w, h)
            .lights(Vec::new())
            .build()
            .expect("valid")
    };
    vec![
        ("default", BakeConfig::default()),
        ("512x512_r_t", no_lights(512, 512)),
        (
            "512x512_r_t_d65_a_f11_sodium",
            BakeConfig::builder()
                .resolution(512, 512)
                .lights(
                    [
                        Illuminant::D65,
                        Illuminant::A,
                        Illuminant::F11,
                        Illuminant::Sodium,
                    ]
                    .map(Light::illuminant)
                    .to_vec(),
                )
                .build()
                .expect("valid"),
        ),
    ]
}

fn bench_bake(c: &mut Criterion) {
    let mut group = c.benchmark_group("bake");
    // Bakes take tens to hundreds of ms; ten samples keep the whole bench under a minute.
    group.sample_size(10);
    for (name, config) in configs() {
        let samples = lut::spectral_samples(&config);
        eprintln!("{name}: {samples} spectral samples");
        group.throughput(Throughput::Elements(samples));
        group.bench_with_input(BenchmarkId::from_parameter(name), &config, |b, config| {
            b.iter(|| lut::bake(config))
        });
    }
    group.finish();
}

fn bench_sample(c: &mut Criterion) {
    let set = lut::bake(&BakeConfig::default());
    let points = lut::accuracy::random_points(4096, 2000.0, 1);
    c.bench_function("sample_4096", |b| {
        b.iter(|| {
            points
                .iter()
                .map(|&(d, c)| set.reflectivity.sample(d, c)[1])
                .sum::<f32>()
        })
    });
}

criterion_group!(benches, bench_bake, bench_sample);
criterion_main!(benches);
