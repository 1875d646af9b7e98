//! A translation correlation of two rasters and its peaks, shared by the
//! map search of the lab's own maps ([`super::mapsearch`]) and of saved
//! real maps ([`super::saved::search`]).
//!
//! Both searches score every whole-cell translation of one raster (B) over
//! the other (A) at once: each wall cell of one raster adds a row of the
//! other's scores into an accumulator indexed by translation, as in Carpin's
//! spectral / Hough-style map merging (Carpin 2008) reduced to the 2-D
//! translation search once a rotation is fixed. The candidates are then the
//! accumulator's strict local maxima, strongest first, kept only when they
//! are far enough from a stronger one (a non-maximum suppression), so that
//! a few distinct overlays are checked rather than one peak's shoulders.

/// Scores of every whole-cell translation `t` of B's raster onto A's:
/// `acc[(ty − ty0)·nx + tx − tx0]`, with `t0 = (tx0, ty0)` the smallest
/// translation held.
pub struct Correlation {
    pub t0: [i64; 2],
    pub nx: usize,
    pub ny: usize,
    pub acc: Vec<i32>,
}

/// `row += add`, element by element (a function of its own so the compiler
/// sees two plain slices and vectorises it).
pub fn add_row(row: &mut [i32], add: &[i32]) {
    for (r, a) in row.iter_mut().zip(add) {
        *r += *a;
    }
}

impl Correlation {
    /// The best `count` positive local maxima at least `apart` cells from
    /// each other, as (translation in cells, score). A plateau counts once
    /// (its first cell in row order); ties sort by position, so the order is
    /// deterministic.
    pub fn peaks(&self, count: usize, apart: f64) -> Vec<([i64; 2], i32)> {
        let (nx, ny, acc) = (self.nx, self.ny, &self.acc);
        let mut local: Vec<(usize, usize, i32)> = Vec::new();
        for y in 1..ny.saturating_sub(1) {
            for x in 1..nx.saturating_sub(1) {
                let v = acc[y * nx + x];
                if v <= 0 {
                    continue;
                }
                let is_max = (0..3).all(|dy| {
                    (0..3).all(|dx| {
                        let w = acc[(y + dy - 1) * nx + x + dx - 1];
                        w < v || (w == v && (dy, dx) >= (1, 1))
                    })
                });
                if is_max {
                    local.push((x, y, v));
                }
            }
        }
        local.sort_by(|p, q| q.2.cmp(&p.2).then(p.1.cmp(&q.1)).then(p.0.cmp(&q.0)));
        let mut out: Vec<([i64; 2], i32)> = Vec::new();
        for (x, y, v) in local {
            if out.len() >= count {
                break;
            }
            let t = [x as i64 + self.t0[0], y as i64 + self.t0[1]];
            let far = out.iter().all(|(u, _)| {
                let (dx, dy) = ((u[0] - t[0]) as f64, (u[1] - t[1]) as f64);
                dx.hypot(dy) >= apart
            });
            if far {
                out.push((t, v));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn peaks_are_separated_local_maxima_strongest_first() {
        // 6 x 5 accumulator, t0 = (-2, 10): a peak of 9 at (1, 1), its
        // shoulder 8 at (2, 1) (not a local maximum), a peak of 7 at (4, 3)
        // and a peak of 5 at (2, 3), 2.0 cells from the 7.
        let (nx, ny) = (6, 5);
        let mut acc = vec![0; nx * ny];
        acc[nx + 1] = 9;
        acc[nx + 2] = 8;
        acc[3 * nx + 4] = 7;
        acc[3 * nx + 2] = 5;
        let c = Correlation {
            t0: [-2, 10],
            nx,
            ny,
            acc,
        };
        assert_eq!(
            c.peaks(5, 1.0),
            vec![([-1, 11], 9), ([2, 13], 7), ([0, 13], 5)]
        );
        // 2.0 cells apart is not far enough at apart = 2.5: (2, 3) goes.
        assert_eq!(c.peaks(5, 2.5), vec![([-1, 11], 9), ([2, 13], 7)]);
        assert_eq!(c.peaks(1, 1.0), vec![([-1, 11], 9)]);
    }
}
