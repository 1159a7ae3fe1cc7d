//! [`Grid`]: the flat mesh before perturbation.

use crate::error::WaterError;

/// Largest number of slices along one side (keeps vertex indices in `u32`).
const MAX_SLICES: usize = 8192;

/// A flat rectangle on the XZ plane at `y = rest_height_m`, cut into `slices[0] × slices[1]`
/// quads (each split into two triangles), so `(slices[0] + 1) × (slices[1] + 1)` vertices.
///
/// # Guarantees
/// Corners and height finite; `min_m < max_m` on both axes; `1 ..= 8192` slices per side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    min_m: [f64; 2],
    max_m: [f64; 2],
    slices: [usize; 2],
    rest_height_m: f64,
}

impl Grid {
    /// A grid from corner `min_m` to `max_m` (X, Z) with `slices` (along X, along Z).
    pub fn try_new(
        min_m: [f64; 2],
        max_m: [f64; 2],
        slices: [usize; 2],
        rest_height_m: f64,
    ) -> Result<Grid, WaterError> {
        let finite = min_m.iter().chain(&max_m).all(|v| v.is_finite());
        if !(finite && min_m[0] < max_m[0] && min_m[1] < max_m[1]) {
            return Err(WaterError::new(
                "water extent",
                format!("min_m {min_m:?} must be finite and below max_m {max_m:?} on X and Z"),
            ));
        }
        if let Some(s) = slices.iter().find(|s| !(1..=MAX_SLICES).contains(*s)) {
            return Err(WaterError::new(
                "water slices",
                format!("{s} must be 1 ..= {MAX_SLICES}"),
            ));
        }
        if !rest_height_m.is_finite() {
            return Err(WaterError::new(
                "water rest_height_m",
                format!("{rest_height_m} must be finite"),
            ));
        }
        Ok(Grid {
            min_m,
            max_m,
            slices,
            rest_height_m,
        })
    }

    /// Slices along X and Z.
    pub fn slices(&self) -> [usize; 2] {
        self.slices
    }

    /// Vertices along X and Z (`slices + 1`).
    pub fn vertices(&self) -> [usize; 2] {
        [self.slices[0] + 1, self.slices[1] + 1]
    }

    /// Corner with the smallest X and Z, in metres.
    pub fn min_m(&self) -> [f64; 2] {
        self.min_m
    }

    /// Corner with the largest X and Z, in metres.
    pub fn max_m(&self) -> [f64; 2] {
        self.max_m
    }

    /// Height of the unperturbed plane, in metres.
    pub fn rest_height_m(&self) -> f64 {
        self.rest_height_m
    }

    /// X of vertex column `i`.
    pub fn x_m(&self, i: usize) -> f64 {
        lerp(self.min_m[0], self.max_m[0], i, self.slices[0])
    }

    /// Z of vertex row `j`.
    pub fn z_m(&self, j: usize) -> f64 {
        lerp(self.min_m[1], self.max_m[1], j, self.slices[1])
    }

    /// Triangles (two per quad, counter-clockwise seen from +Y), indexing vertices row by row.
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        let [nx, nz] = self.vertices();
        let mut out = Vec::with_capacity(2 * self.slices[0] * self.slices[1]);
        for j in 0..nz - 1 {
            for i in 0..nx - 1 {
                let v00 = (j * nx + i) as u32;
                let (v10, v01) = (v00 + 1, v00 + nx as u32);
                out.push([v00, v01, v10]);
                out.push([v10, v01, v01 + 1]);
            }
        }
        out
    }
}

/// Exact at both ends: `a` at 0 and `b` at `n`.
fn lerp(a: f64, b: f64, i: usize, n: usize) -> f64 {
    let t = i as f64 / n as f64;
    a * (1.0 - t) + b * t
}
