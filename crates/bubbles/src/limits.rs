//! Every bound on the work and memory a user can ask for, in one place.
//!
//! Each limit keeps one run within [`MEMORY_BUDGET_BYTES`] and a bounded number of
//! steps, frames and files; `--help` prints them through [`HELP`]. A request beyond a
//! limit is refused before any work starts, with exit code 2 and a message naming the
//! limit.

/// Memory one run may plan to allocate for its large buffers (cube maps, frame buffers,
/// decoded textures, opaque triangles, bubble meshes), in bytes.
pub const MEMORY_BUDGET_BYTES: u64 = 3 << 30;

/// Solver steps one `render` or `simulate` may take (`time_s / dt_s`).
pub const MAX_SOLVER_STEPS: u64 = 1_000_000;

/// OBJ files one `simulate --export-obj` may write.
pub const MAX_OBJ_FRAMES: u64 = 10_000;

/// Frames `bench --frames` may time at each size.
pub const MAX_BENCH_FRAMES: u32 = 100_000;

/// Largest dynamic cube-map face, in texels (`--cube-map-size`, `[render] cube_map_size`).
pub const MAX_CUBE_MAP_SIZE: usize = 1024;

/// Film-table columns over thickness (`--lut-thickness-samples`,
/// `[render] lut_thickness_samples`): `lut`'s largest side.
pub const MAX_LUT_THICKNESS_SAMPLES: usize = lut::MAX_SIDE;

/// Film-table rows over cos θ (`--lut-angle-samples`, `[render] lut_angle_samples`).
pub const MAX_LUT_ANGLE_SAMPLES: usize = 1024;

/// Largest icosphere subdivision level of a bubble (6 gives 40 962 vertices).
pub const MAX_SUBDIVISIONS: u32 = 6;

/// Largest image side, in pixels (`--width`, `--height`, `bench --size`).
pub const MAX_IMAGE_SIDE: usize = raster::MAX_IMAGE_SIDE;

/// Bubbles in one scene.
pub const MAX_BUBBLES: usize = 1000;

/// Bubble vertices in one scene, summed over its bubbles.
pub const MAX_BUBBLE_VERTICES: usize = 1_000_000;

/// Film-flow cells in one scene, summed over its bubbles (`6·film_grid²` each): one
/// 512-cell grid or four of 256 (each cell holds about 400 bytes with its edges, the
/// multigrid levels and the scratch: 0.6 GB at the limit).
pub const MAX_FILM_CELLS: usize = 6 * 512 * 512;

/// Film-flow cells of one bubble's grid of `film_grid` cells a face side.
pub fn film_cells(film_grid: u32) -> usize {
    6 * (film_grid as usize).pow(2)
}

/// Opaque objects (spheres, boxes, meshes) in one scene.
pub const MAX_OBJECTS: usize = 1000;

/// Lights in one scene.
pub const MAX_LIGHTS: usize = 64;

/// Opaque triangles in one scene, after tessellation (a sphere is 2304).
pub const MAX_OPAQUE_TRIANGLES: u64 = 4_000_000;

/// Slices along one side of the water grid (a 512 × 512 grid has 263 169 vertices and
/// 524 288 triangles, drawn twice a frame: once seen, once in its reflection cube map).
pub const MAX_WATER_SLICES: usize = 512;

/// Waves and ripples on the water, together.
pub const MAX_WATER_PERTURBATIONS: usize = 64;

/// Pixels of one decoded image (environment, texture, cube face), checked before decoding.
pub const MAX_IMAGE_PIXELS: u64 = 64 << 20;

/// Bytes of one text input: a scene, an OBJ mesh, a spectrum CSV.
pub const MAX_INPUT_BYTES: u64 = 64 << 20;

/// Largest value of an image texel (environment, cube face, ground or object texture)
/// times its `intensity`, per channel: the scene's radiance range, in which sums over a
/// cube map's texels and their products with exposure stay finite in f32.
pub const MAX_TEXEL_RADIANCE: f64 = 1e6;

/// Smallest refractive index (real part) any command accepts: far below any material's.
pub const MIN_INDEX: f64 = thinfilm::fresnel::MIN_INDEX;

/// Largest refractive index (real or imaginary part) any command accepts.
pub const MAX_INDEX: f64 = thinfilm::fresnel::MAX_INDEX;

/// Thickest layer `reflectance`, `fit` and `color` accept, in nm (1 m).
pub const MAX_LAYER_THICKNESS_NM: f64 = thinfilm::fresnel::MAX_THICKNESS_NM;

/// Film interactions the reference tracer may plan for one frame (2^42, about 4.4e12):
/// its work bound, see [`reference_film_hits`].
pub const MAX_REFERENCE_FILM_HITS: f64 = (1u64 << 42) as f64;

/// The most film interactions `--backend reference` can trace for a frame: every camera
/// ray (at most `max_samples` per pixel) may split at each film into a reflected and a
/// transmitted beam until `depth` films, `2^(depth+1) − 1` interactions (the weight
/// cut-off prunes many, but grazing films reflect almost everything, so it bounds none).
pub fn reference_film_hits(width: usize, height: usize, max_samples: u32, depth: u32) -> f64 {
    let rays = width as f64 * height as f64 * f64::from(max_samples);
    rays * (2f64.powf(f64::from(depth) + 1.0) - 1.0)
}

/// The limits as printed at the end of `--help`.
pub const HELP: &str = "Limits (a larger request is refused with exit code 2):
  solver steps per run (time_s / dt_s)        1000000
  OBJ frames per simulate --export-obj        10000
  bench --frames                              100000
  cube_map_size / --cube-map-size             1..=1024 texels
  lut_thickness_samples / --lut-thickness-samples  2..=16384 columns
  lut_angle_samples / --lut-angle-samples     2..=1024 rows
  bubble subdivisions                         0..=6
  --width, --height, bench --size             1..=16384 pixels
  bubbles per scene                           1000 (1000000 vertices in all)
  film-flow cells per scene (6 film_grid²)    1572864
  objects per scene                           1000 (4000000 triangles in all)
  lights per scene                            64
  water slices per side                       1..=512
  water waves and ripples                     64
  pixels of one image file                    67108864
  bytes of one scene, OBJ or CSV file         67108864
  image texel times intensity                 0..=1e6
  refractive index (real part)                0.001..=1e6
  layer thickness (reflectance, fit, color)   0..=1e9 nm
  reference film hits per frame               4398046511104
    (pixels × ref-max-samples × (2^(ref-depth+1) − 1))
  planned memory of one run                   3 GiB";

/// Bytes of one dynamic cube map of `face_size` (six bordered faces of RGB f32 and their
/// mip chain, plus the depth and triangle scratch the renderer keeps per level-0 face).
pub fn cube_map_bytes(face_size: usize) -> u64 {
    let side = face_size as u64 + 2;
    raster::CubeMap::stored_texels(face_size) as u64 * 12 + 6 * side * side * 8
}

/// Bytes of the baked film tables: `tables` RGB f32 tables of `width × height` texels.
pub fn lut_bytes(width: usize, height: usize, tables: usize) -> u64 {
    width as u64 * height as u64 * 12 * tables as u64
}

/// Bytes per texel of one baked table held in memory (RGB f32).
pub const BAKE_TABLE_BYTES_PER_TEXEL: u64 = 12;

/// Bytes per texel a writer holds on top of the tables while it encodes one table: EXR
/// streams from the table itself (blocks of lines); a 16-bit PNG holds its codes, their
/// big-endian copy and the compressed stream (at most about the codes' size); the 8-bit
/// preview its bytes and their compressed stream. Measured at 4096 × 2048 as peak
/// resident memory above the tables' own: 0.03, 15.2 and 3.6 (docs/lut.md).
pub fn bake_writer_bytes_per_texel(format: lut::Format) -> u64 {
    match format {
        lut::Format::Exr => 1,
        lut::Format::Png16 => 18,
        lut::Format::Png8 => 6,
    }
}

/// Bytes `bake` plans for `width × height` tables with `lights` light tables written in
/// `formats`: every table it holds until the files are written (reflectivity,
/// transmittance, one per light), plus the largest writer, which runs one table at a time.
pub fn bake_bytes(width: usize, height: usize, lights: usize, formats: &[lut::Format]) -> u64 {
    let texels = width as u64 * height as u64;
    let tables = (2 + lights as u64) * texels * BAKE_TABLE_BYTES_PER_TEXEL;
    let writer = formats
        .iter()
        .map(|&f| bake_writer_bytes_per_texel(f))
        .max()
        .unwrap_or(0);
    tables + texels * writer
}

/// Bytes of the frame buffers for `width × height` at `samples` per pixel (HDR colour
/// and depth per sample, plus the resolved image).
pub fn frame_bytes(width: usize, height: usize, samples: u32) -> u64 {
    let pixels = width as u64 * height as u64;
    pixels * (u64::from(samples) * 16 + 16)
}

/// Vertices of an icosphere with `subdivisions` levels: 10·4ˢ + 2.
pub fn icosphere_vertices(subdivisions: u32) -> usize {
    10 * 4_usize.pow(subdivisions.min(MAX_SUBDIVISIONS)) + 2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bake_plans_every_table_and_the_largest_writer() {
        use lut::Format::{Exr, Png8, Png16};
        let texels = 16384 * 4096;
        // Issue 28's bake: seven lights, three formats; 7.9 GiB, refused.
        let bytes = bake_bytes(16384, 4096, 7, &[Exr, Png16, Png8]);
        assert_eq!(bytes, texels * (9 * 12 + 18));
        assert!(bytes > MEMORY_BUDGET_BYTES);
        // One writer runs at a time: the largest counts, not the sum.
        assert_eq!(bake_bytes(100, 10, 0, &[Png8, Exr]), 1000 * (2 * 12 + 6));
        // The largest table with one light, written as EXR only, fits.
        assert!(bake_bytes(16384, 4096, 1, &[Exr]) <= MEMORY_BUDGET_BYTES);
    }

    #[test]
    fn help_states_the_constants() {
        for value in [
            MAX_SOLVER_STEPS,
            MAX_OBJ_FRAMES,
            u64::from(MAX_BENCH_FRAMES),
            MAX_CUBE_MAP_SIZE as u64,
            MAX_LUT_THICKNESS_SAMPLES as u64,
            MAX_LUT_ANGLE_SAMPLES as u64,
            MAX_IMAGE_SIDE as u64,
            MAX_BUBBLES as u64,
            MAX_BUBBLE_VERTICES as u64,
            MAX_FILM_CELLS as u64,
            MAX_OBJECTS as u64,
            MAX_LIGHTS as u64,
            MAX_OPAQUE_TRIANGLES,
            MAX_IMAGE_PIXELS,
            MAX_INPUT_BYTES,
            MAX_REFERENCE_FILM_HITS as u64,
        ] {
            assert!(
                HELP.contains(&value.to_string()),
                "{value} missing from HELP"
            );
        }
        assert!(HELP.contains(&format!("0..={MAX_SUBDIVISIONS}")));
        assert!(HELP.contains(&format!("1..={MAX_WATER_SLICES}")));
        assert!(HELP.contains(&format!(
            "ripples                     {MAX_WATER_PERTURBATIONS}"
        )));
        assert!(HELP.contains(&format!("{} GiB", MEMORY_BUDGET_BYTES >> 30)));
    }

    #[test]
    fn reference_work_counts_every_split_up_to_the_depth() {
        // 4 × 4 pixels, at most 16 rays each, depth 1: the film, then its two beams' films.
        assert_eq!(reference_film_hits(4, 4, 16, 1), 256.0 * 3.0);
        // Issue 28: depth 64 on 4 × 4 pixels is far past the bound, the default 400 × 400
        // frame (up to 1024 rays a pixel) at depth 8 is within it, and so is the largest
        // frame at depth 8 with 16 rays a pixel; with up to 1024 it must be refused.
        assert!(reference_film_hits(4, 4, 16, 64) > MAX_REFERENCE_FILM_HITS);
        assert!(reference_film_hits(400, 400, 1024, 8) < MAX_REFERENCE_FILM_HITS);
        assert!(reference_film_hits(16384, 16384, 16, 8) < MAX_REFERENCE_FILM_HITS);
        assert!(reference_film_hits(16384, 16384, 1024, 8) > MAX_REFERENCE_FILM_HITS);
    }

    #[test]
    fn icosphere_vertex_count_matches_the_solver() {
        assert_eq!(icosphere_vertices(3), 642, "seed 000's 642 vertices");
        assert_eq!(icosphere_vertices(0), 12);
    }
}
