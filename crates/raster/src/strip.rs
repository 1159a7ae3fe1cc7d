//! Strips: the unit of parallel work. A strip is [`STRIP_ROWS`] full image rows; it owns
//! its pixels' samples outright, so strips run in parallel with no shared writes, and each
//! walks its triangles ([`Bins`]) in one fixed order.

use crate::raster::SetupTri;

/// Rows per strip (the unit of parallel work).
pub(crate) const STRIP_ROWS: usize = 8;

/// Triangle indices per strip, in submission order (a counting sort).
#[derive(Debug, Clone, Default)]
pub(crate) struct Bins {
    starts: Vec<u32>,
    items: Vec<u32>,
}

impl Bins {
    /// Rebuilds the bins of `tris` for `strips` strips.
    pub fn build(&mut self, tris: &[SetupTri], strips: usize) {
        let range = |t: &SetupTri| {
            (
                t.bbox[1] as usize / STRIP_ROWS,
                (t.bbox[3] as usize - 1) / STRIP_ROWS,
            )
        };
        self.starts.clear();
        self.starts.resize(strips + 2, 0);
        for t in tris {
            let (a, b) = range(t);
            for s in a..=b.min(strips - 1) {
                self.starts[s + 2] += 1;
            }
        }
        for s in 2..self.starts.len() {
            self.starts[s] += self.starts[s - 1];
        }
        self.items.clear();
        self.items.resize(self.starts[strips + 1] as usize, 0);
        // starts[s + 1] is now the write cursor of strip s.
        for (i, t) in tris.iter().enumerate() {
            let (a, b) = range(t);
            for s in a..=b.min(strips - 1) {
                let cursor = &mut self.starts[s + 1];
                self.items[*cursor as usize] = i as u32;
                *cursor += 1;
            }
        }
    }

    /// Triangle indices touching strip `s`.
    pub fn strip(&self, s: usize) -> &[u32] {
        &self.items[self.starts[s] as usize..self.starts[s + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bins_list_each_triangle_in_every_strip_it_touches_in_order() {
        let tri = |y0: i32, y1: i32| SetupTri {
            bbox: [0, y0, 4, y1],
            ..SetupTri::default()
        };
        let tris = [tri(0, 3), tri(5, 20), tri(8, 9), tri(30, 32)];
        let mut bins = Bins::default();
        bins.build(&tris, 4);
        assert_eq!(bins.strip(0), &[0, 1]);
        assert_eq!(bins.strip(1), &[1, 2]);
        assert_eq!(bins.strip(2), &[1]);
        assert_eq!(bins.strip(3), &[3]);
    }
}
