//! # Multi-resolution correlative scan matching
//!
//! E. Olson, *Real-Time Correlative Scan Matching*, ICRA 2009. Given a prior
//! pose (here: the last estimate moved by the odometry increment), search a
//! window of poses around it — every rotation in `±angular_window` at
//! `angular_step`, and every whole-cell translation in `±linear_window` —
//! for the one whose laser end points land on the most wall-like cells of
//! the [`LikelihoodField`] (§III: the score is the sum of the field over
//! the points).
//!
//! Brute force would score every (θ, x, y). Olson's two-level trick (§IV):
//! for each rotation the points are rotated once; then translations are
//! scored first on the *coarse* table, whose entries are maxima over `K × K`
//! fine cells, so one coarse score bounds all `K²` fine scores of its block.
//! Candidates are sorted best first and expanded to fine resolution until
//! the next coarse bound cannot beat the best fine score found: the answer
//! is the exact optimum of the full fine search at a small part of its cost.
//! Ties go to the candidate nearest the prior, so a flat response (a
//! featureless corridor) does not pull the pose anywhere.
//!
//! A window metres wide (a loop closure's, grown with the path since the
//! place was seen) has thousands of coarse blocks at each rotation, and
//! scoring them all becomes the cost. Such a search adds a third level, as
//! Cartographer's branch and bound stacks several (Hess et al., *Real-Time
//! Loop Closure in 2D LIDAR SLAM*, ICRA 2016, §V-C): groups of 4 × 4 coarse
//! blocks bounded by one table of maxima, whose blocks are scored only when
//! the group's bound can still win. A priority queue hands the blocks out
//! in exactly the flat search's order, so both return the same pose.
//!
//! The result is accurate to one cell and `angular_step`; the mapper
//! refines it with [`super::surface`] (or, on a grid without surface means,
//! [`super::gauss_newton`]). The mapper searches only when refining from
//! the prior finds too few points on mapped surfaces — the prior is then off
//! by more than the refinement can see, as after a long stretch without
//! matches or on returning to an area mapped long ago; a step's odometry is
//! otherwise good to millimetres and the search would cost ten times the
//! refinement for nothing.

use super::likelihood::LikelihoodField;
use crate::geom::{wrap_angle, Pose2};
use glam::DVec2;

/// The search window.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CorrelativeConfig {
    pub linear_window_m: f64,
    pub angular_window_rad: f64,
    pub angular_step_rad: f64,
    /// Coarse block size in fine cells (Olson's low-resolution factor).
    pub coarse_cells: usize,
}

impl Default for CorrelativeConfig {
    fn default() -> Self {
        CorrelativeConfig {
            linear_window_m: 0.3,
            angular_window_rad: 3f64.to_radians(),
            angular_step_rad: 0.5f64.to_radians(),
            coarse_cells: 4,
        }
    }
}

/// The best pose of the search.
#[derive(Clone, Debug, PartialEq)]
pub struct CorrelativeMatch {
    pub pose: Pose2,
    /// Mean field value at the points (0..1).
    pub score: f64,
    /// Fine-resolution poses scored (for the benchmark's curiosity).
    pub fine_evaluations: usize,
}

/// Searches the window around `prior` for the pose that best lays
/// `points` (robot frame) on the field. `None` without points.
pub fn search(
    field: &LikelihoodField,
    points: &[DVec2],
    prior: &Pose2,
    cfg: &CorrelativeConfig,
) -> Option<CorrelativeMatch> {
    search_outside(field, points, prior, cfg, None)
}

/// Positions a search leaves out: every pose whose position lies within
/// `radius_m` of `centre` along both axes, at any heading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Exclusion {
    pub centre: DVec2,
    pub radius_m: f64,
}

/// [`search`] over the window less `exclude`: the best pose elsewhere, to
/// tell a unique match from one of a pattern that repeats (a corridor's
/// doors). The coarse bounds still bound every pose they cover, so the
/// branch and bound stays exact over what is left. `None` without points
/// or when nothing is left.
pub fn search_outside(
    field: &LikelihoodField,
    points: &[DVec2],
    prior: &Pose2,
    cfg: &CorrelativeConfig,
    exclude: Option<Exclusion>,
) -> Option<CorrelativeMatch> {
    search_blocks(field, points, prior, cfg, exclude, DEEP_MIN_BLOCKS)
}

/// [`search_outside`], with the third level from `deep_from` coarse blocks
/// along each axis on.
fn search_blocks(
    field: &LikelihoodField,
    points: &[DVec2],
    prior: &Pose2,
    cfg: &CorrelativeConfig,
    exclude: Option<Exclusion>,
    deep_from: usize,
) -> Option<CorrelativeMatch> {
    if points.is_empty() {
        return None;
    }
    let res = field.resolution_m;
    let w = (cfg.linear_window_m / res).round() as i64;
    let k = field.k as i64;
    let nt = (cfg.angular_window_rad / cfg.angular_step_rad).round() as i64;
    let scan = Rotated::new(field, points, prior, cfg.angular_step_rad, nt);
    // Coarse candidates: every block of `k × k` translations at every
    // rotation, bounded by the coarse table.
    let starts: Vec<i64> = (0..).map(|i| -w + i * k).take_while(|&o| o <= w).collect();
    let mut bnb = BranchAndBound {
        best: None,
        evaluations: 0,
        w,
        k,
        nt,
        excluded: Excluded::new(exclude, prior, res),
        scratch: Vec::new(),
    };
    if starts.len() < deep_from {
        blocks_flat(&scan, &starts, &mut bnb);
    } else {
        blocks_deep(&scan, &starts, &mut bnb);
    }
    let (s, t, ox, oy) = bnb.best?;
    Some(CorrelativeMatch {
        pose: Pose2::new(
            prior.x + ox as f64 * res,
            prior.y + oy as f64 * res,
            wrap_angle(prior.theta + t as f64 * cfg.angular_step_rad),
        ),
        score: s as f64 / points.len() as f64,
        fine_evaluations: bnb.evaluations,
    })
}

/// The points of a search turned to each of its `2 nt + 1` rotations, as
/// window cells of the field.
struct Rotated<'a> {
    field: &'a LikelihoodField,
    n: usize,
    n_theta: usize,
    cells: Vec<[i64; 2]>,
}

impl<'a> Rotated<'a> {
    fn new(
        field: &'a LikelihoodField,
        points: &[DVec2],
        prior: &Pose2,
        step_rad: f64,
        nt: i64,
    ) -> Self {
        let n_theta = (2 * nt + 1) as usize;
        let mut cells = Vec::with_capacity(points.len() * n_theta);
        for t in -nt..=nt {
            let theta = prior.theta + t as f64 * step_rad;
            let frame = Pose2::new(prior.x, prior.y, theta).frame();
            cells.extend(points.iter().map(|&p| field.cell_of(frame.to_parent(p))));
        }
        Rotated {
            field,
            n: points.len(),
            n_theta,
            cells,
        }
    }

    fn rotations(&self) -> usize {
        self.n_theta
    }

    /// The sums of `table` (laid out as the field's) over the points at
    /// rotation `ti`, shifted by every `(xs[i], ys[j])` cells (both
    /// ascending), into `out[j * xs.len() + i]`; cells beyond the table
    /// count 0.
    ///
    /// The points are the outer loop: each point's shifts read a few nearby
    /// cells — side by side for a block's fine shifts, one slice per row,
    /// which the compiler adds as vectors — instead of the whole table once
    /// per shift. A shift whose cell lies beyond the table is skipped
    /// rather than adding 0 to a non-negative sum, which leaves it as it
    /// is. So every sum adds the same values in the same order as a sum per
    /// shift, bit for bit.
    fn sums(&self, table: &[f32], ti: usize, xs: &[i64], ys: &[i64], out: &mut Vec<f32>) {
        let nx = xs.len();
        out.clear();
        out.resize(nx * ys.len(), 0.0);
        let (Some(&x0), Some(&x1), Some(&y0), Some(&y1)) =
            (xs.first(), xs.last(), ys.first(), ys.last())
        else {
            return;
        };
        let (wd, ht) = (self.field.width as i64, self.field.height as i64);
        let contiguous = xs.iter().zip(x0..).all(|(&x, y)| x == y);
        for c in &self.cells[ti * self.n..(ti + 1) * self.n] {
            let inside = c[0] + x0 >= 0 && c[0] + x1 < wd && c[1] + y0 >= 0 && c[1] + y1 < ht;
            for (row, &oy) in out.chunks_exact_mut(nx).zip(ys) {
                let y = c[1] + oy;
                if inside && contiguous {
                    let at = (y * wd + c[0] + x0) as usize;
                    add(row, &table[at..at + nx]);
                } else if inside {
                    let at = y * wd + c[0];
                    for (acc, &ox) in row.iter_mut().zip(xs) {
                        *acc += table[(at + ox) as usize];
                    }
                } else if (0..ht).contains(&y) {
                    for (acc, &ox) in row.iter_mut().zip(xs) {
                        let x = c[0] + ox;
                        if (0..wd).contains(&x) {
                            *acc += table[(y * wd + x) as usize];
                        }
                    }
                }
            }
        }
    }
}

/// `acc[i] += v[i]` (equal lengths).
fn add(acc: &mut [f32], v: &[f32]) {
    for (a, &b) in acc.iter_mut().zip(v) {
        *a += b;
    }
}

/// The box a search leaves out, in cell offsets from the prior (none: an
/// empty box, radius −1).
#[derive(Clone, Copy)]
struct Excluded {
    x: i64,
    y: i64,
    r: i64,
}

impl Excluded {
    fn new(exclude: Option<Exclusion>, prior: &Pose2, res: f64) -> Self {
        match exclude {
            Some(e) => {
                let c = (e.centre - prior.position()) / res;
                Excluded {
                    x: c.x.round() as i64,
                    y: c.y.round() as i64,
                    r: (e.radius_m / res).ceil() as i64,
                }
            }
            None => Excluded { x: 0, y: 0, r: -1 },
        }
    }
}

/// The fine level of the branch and bound: the best pose so far (score,
/// rotation, offsets) and the poses scored.
struct BranchAndBound {
    best: Option<(f32, i64, i64, i64)>,
    evaluations: usize,
    w: i64,
    k: i64,
    nt: i64,
    excluded: Excluded,
    /// The block's fine sums, kept between visits.
    scratch: Vec<f32>,
}

impl BranchAndBound {
    /// Whether a block bounded by `score` can still beat the best pose.
    fn open(&self, score: f32) -> bool {
        self.best.is_none_or(|(b, ..)| score >= b - 1e-4)
    }

    /// Scores every pose of block `c` at fine resolution; false (and
    /// nothing scored) once the blocks left cannot win.
    fn visit(&mut self, scan: &Rotated, c: &Candidate) -> bool {
        if !self.open(c.score) {
            return false;
        }
        let (w, k, e) = (self.w, self.k, self.excluded);
        let dist = |t: i64, x: i64, y: i64| t.abs() + x.abs() + y.abs();
        let ti = (c.t + self.nt) as usize;
        // Whether this block meets the excluded box (never without one).
        let meets = e.r >= 0
            && c.ox <= e.x + e.r
            && c.ox + k > e.x - e.r
            && c.oy <= e.y + e.r
            && c.oy + k > e.y - e.r;
        let xs: Vec<i64> = (c.ox..(c.ox + k).min(w + 1)).collect();
        let ys: Vec<i64> = (c.oy..(c.oy + k).min(w + 1)).collect();
        let mut sums = std::mem::take(&mut self.scratch);
        scan.sums(&scan.field.fine, ti, &xs, &ys, &mut sums);
        for (row, &oy) in sums.chunks_exact(xs.len().max(1)).zip(&ys) {
            for (&s, &ox) in row.iter().zip(&xs) {
                if meets && (ox - e.x).abs() <= e.r && (oy - e.y).abs() <= e.r {
                    continue;
                }
                self.evaluations += 1;
                let better = match self.best {
                    None => true,
                    Some((b, bt, bx, by)) => {
                        s > b + 1e-4 || (s >= b - 1e-4 && dist(c.t, ox, oy) < dist(bt, bx, by))
                    }
                };
                if better {
                    self.best = Some((s, c.t, ox, oy));
                }
            }
        }
        self.scratch = sums;
        true
    }
}

/// The two-level search: every coarse block scored, taken best first
/// (equal scores in the order scored) from a heap, and expanded until the
/// next cannot win.
fn blocks_flat(scan: &Rotated, starts: &[i64], bnb: &mut BranchAndBound) {
    let per_axis = starts.len();
    let mut blocks = Vec::with_capacity(scan.rotations() * per_axis * per_axis);
    let coarse = &scan.field.coarse;
    let mut sums = Vec::new();
    for ti in 0..scan.rotations() {
        scan.sums(coarse, ti, starts, starts, &mut sums);
        for &score in &sums {
            let order = blocks.len() as u32;
            blocks.push(Queued {
                score,
                group: false,
                order,
            });
        }
    }
    // A heap hands the blocks out best first without sorting those the
    // search never reaches.
    let mut queue = std::collections::BinaryHeap::from(blocks);
    while let Some(q) = queue.pop() {
        if !bnb.visit(scan, &block(&q, starts, bnb.nt)) {
            break;
        }
    }
}

/// The coarse block `q` (not a group) stands for.
fn block(q: &Queued, starts: &[i64], nt: i64) -> Candidate {
    let (o, per_axis) = (q.order as usize, starts.len());
    let (ti, iy, ix) = (
        o / (per_axis * per_axis),
        o / per_axis % per_axis,
        o % per_axis,
    );
    Candidate {
        score: q.score,
        t: ti as i64 - nt,
        ox: starts[ix],
        oy: starts[iy],
    }
}

/// The three-level search (see [`DEEP_MIN_BLOCKS`]): groups of coarse
/// blocks bounded by the top table, a group's blocks scored only when it
/// is taken from the queue, the blocks taken in [`blocks_flat`]'s order.
fn blocks_deep(scan: &Rotated, starts: &[i64], bnb: &mut BranchAndBound) {
    let top = top_table(scan.field);
    let per_axis = starts.len();
    let groups = per_axis.div_ceil(TOP_BLOCKS);
    let mut queue = std::collections::BinaryHeap::new();
    let firsts: Vec<i64> = starts.iter().step_by(TOP_BLOCKS).copied().collect();
    let coarse = &scan.field.coarse;
    let mut sums = Vec::new();
    for ti in 0..scan.rotations() {
        scan.sums(&top, ti, &firsts, &firsts, &mut sums);
        for (g, &score) in sums.iter().enumerate() {
            queue.push(Queued {
                score,
                group: true,
                order: (ti * groups * groups + g) as u32,
            });
        }
    }
    while let Some(q) = queue.pop() {
        if !bnb.open(q.score) {
            break;
        }
        let o = q.order as usize;
        if q.group {
            let (ti, gy, gx) = (o / (groups * groups), o / groups % groups, o % groups);
            let iys = gy * TOP_BLOCKS..((gy + 1) * TOP_BLOCKS).min(per_axis);
            let ixs = gx * TOP_BLOCKS..((gx + 1) * TOP_BLOCKS).min(per_axis);
            let (ys, xs) = (&starts[iys.clone()], &starts[ixs.clone()]);
            scan.sums(coarse, ti, xs, ys, &mut sums);
            let blocks = iys.flat_map(|iy| ixs.clone().map(move |ix| (ix, iy)));
            for (&score, (ix, iy)) in sums.iter().zip(blocks) {
                queue.push(Queued {
                    score,
                    group: false,
                    order: ((ti * per_axis + iy) * per_axis + ix) as u32,
                });
            }
        } else if !bnb.visit(scan, &block(&q, starts, bnb.nt)) {
            break;
        }
    }
}

/// A coarse block of [`search_outside`]'s branch and bound.
struct Candidate {
    score: f32,
    t: i64,
    ox: i64,
    oy: i64,
}

/// From this many coarse blocks along each axis of the window on, the
/// search adds a third level: groups of [`TOP_BLOCKS`] × [`TOP_BLOCKS`]
/// coarse blocks bounded by one table ([`top_table`]), and scores a group's
/// coarse blocks only when the group's bound can still beat the best pose.
/// A loop closure's window grown to ±8 m at 5 cm holds 41 × 41 coarse
/// blocks at each of some 170 rotations; scoring them all was most of the
/// search. The blocks are then taken from a priority queue in exactly the
/// order the flat search sorts them (score, then the order scored; a group
/// before a block of equal score, since its blocks may score that too), so
/// both searches visit the same blocks and return the same pose.
const DEEP_MIN_BLOCKS: usize = 12;

/// Coarse blocks per group along each axis (see [`DEEP_MIN_BLOCKS`]).
const TOP_BLOCKS: usize = 4;

/// A group or a coarse block in the queue of the three-level search: best
/// score first, a group before a block of equal score, then the lower
/// order.
struct Queued {
    score: f32,
    group: bool,
    order: u32,
}

impl PartialEq for Queued {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == std::cmp::Ordering::Equal
    }
}

impl Eq for Queued {}

impl PartialOrd for Queued {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Queued {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.score
            .total_cmp(&other.score)
            .then(self.group.cmp(&other.group))
            .then(other.order.cmp(&self.order))
    }
}

/// The maximum of the coarse table over [`TOP_BLOCKS`] × [`TOP_BLOCKS`]
/// blocks from each cell: `top[x, y]` bounds the fine table over
/// `[x, x + TOP_BLOCKS · k)` on both axes (cells beyond the table count 0).
fn top_table(field: &LikelihoodField) -> Vec<f32> {
    let (wd, ht, k) = (field.width, field.height, field.k);
    let mut rows = vec![0f32; wd * ht];
    for y in 0..ht {
        let src = &field.coarse[y * wd..(y + 1) * wd];
        let dst = &mut rows[y * wd..(y + 1) * wd];
        for (x, d) in dst.iter_mut().enumerate() {
            *d = (0..TOP_BLOCKS)
                .map(|i| x + i * k)
                .take_while(|&xi| xi < wd)
                .fold(0f32, |m, xi| m.max(src[xi]));
        }
    }
    let mut top = vec![0f32; wd * ht];
    for y in 0..ht {
        for i in 0..TOP_BLOCKS {
            let yi = y + i * k;
            if yi >= ht {
                break;
            }
            let (src, dst) = (
                &rows[yi * wd..(yi + 1) * wd],
                &mut top[y * wd..(y + 1) * wd],
            );
            for (d, &v) in dst.iter_mut().zip(src) {
                *d = d.max(v);
            }
        }
    }
    top
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slam::multires::field_from_points;
    use crate::slam::scenes;

    /// A window of ±6 m (31 coarse blocks a side): the three-level search
    /// visits the same blocks as the flat one and returns the same pose,
    /// with a box left out or not, and that pose is the truth's.
    #[test]
    fn the_three_level_search_is_the_flat_one() {
        let walls = scenes::room();
        let truth = Pose2::new(6.2, 2.9, 0.1);
        let map_from = Pose2::new(5.0, 3.0, 0.0);
        let f = map_from.frame();
        let world: Vec<DVec2> = scenes::scan(&map_from, &walls, 10.0)
            .into_iter()
            .map(|p| f.to_parent(p))
            .collect();
        let field = field_from_points(&world, 0.05, 8, 7.0);
        let points = scenes::scan(&truth, &walls, 10.0);
        let prior = Pose2::new(truth.x - 3.7, truth.y + 1.6, truth.theta + 0.03);
        let cfg = CorrelativeConfig {
            linear_window_m: 6.0,
            angular_window_rad: 4f64.to_radians(),
            angular_step_rad: 0.5f64.to_radians(),
            coarse_cells: 8,
        };
        let exclusions = [
            None,
            Some(Exclusion {
                centre: truth.position(),
                radius_m: 0.5,
            }),
        ];
        for exclude in exclusions {
            let deep = search_blocks(&field, &points, &prior, &cfg, exclude, DEEP_MIN_BLOCKS);
            let flat = search_blocks(&field, &points, &prior, &cfg, exclude, usize::MAX);
            assert_eq!(deep, flat);
        }
        let m = search_outside(&field, &points, &prior, &cfg, None).unwrap();
        assert!(m.pose.position().distance(truth.position()) < 0.08, "{m:?}");
        assert!(wrap_angle(m.pose.theta - truth.theta).abs() < 0.5f64.to_radians());
        // A corridor: along it every block scores alike, and the order of
        // equal scores decides.
        let walls = scenes::corridor();
        let world: Vec<DVec2> = scenes::scan(&map_from, &walls, 10.0)
            .into_iter()
            .map(|p| f.to_parent(p))
            .collect();
        let field = field_from_points(&world, 0.05, 8, 7.0);
        let points = scenes::scan(&Pose2::new(5.3, 0.9, 0.0), &walls, 10.0);
        let prior = Pose2::new(3.1, 1.2, 0.02);
        for exclude in exclusions {
            let deep = search_blocks(&field, &points, &prior, &cfg, exclude, DEEP_MIN_BLOCKS);
            let flat = search_blocks(&field, &points, &prior, &cfg, exclude, usize::MAX);
            assert_eq!(deep, flat);
        }
    }

    /// The top table is the maximum of the coarse one over 4 × 4 blocks
    /// from each cell, cells beyond the table left out.
    #[test]
    fn the_top_table_bounds_its_blocks() {
        let walls = scenes::room();
        let pose = Pose2::new(5.0, 3.0, 0.0);
        let f = pose.frame();
        let world: Vec<DVec2> = scenes::scan(&pose, &walls, 10.0)
            .into_iter()
            .map(|p| f.to_parent(p))
            .collect();
        let field = field_from_points(&world, 0.05, 8, 1.0);
        let top = top_table(&field);
        let (wd, ht, k) = (field.width, field.height, field.k);
        for y in (0..ht).step_by(7) {
            for x in (0..wd).step_by(5) {
                let mut m = 0f32;
                for j in 0..TOP_BLOCKS {
                    for i in 0..TOP_BLOCKS {
                        m = m.max(field.coarse_at((x + i * k) as i64, (y + j * k) as i64));
                    }
                }
                assert_eq!(top[y * wd + x], m, "cell ({x}, {y})");
            }
        }
    }
}
