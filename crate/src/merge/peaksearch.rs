//! # The best translations without scoring them all: branch and bound
//!
//! The map search ([`super::mapsearch`]) scores every whole-cell
//! translation `t` of map B's raster over map A's:
//!
//! ```text
//! score(t) = Σ_{w ∈ B's walls} A(w + t)  +  Σ_{w ∈ A's walls} B(w − t)
//! ```
//!
//! (a cell's score is +1 near a wall, −`free_penalty` in sure free space,
//! 0 when unknown or outside the raster), and keeps the best few local
//! maxima that lie `apart` from each other
//! ([`super::raster_correlation::Correlation::peaks`]). Done exhaustively, that is
//! every wall of one map times every cell of the other: quadratic in the
//! maps' area. On 60 m maps at 0.1 m it is about 4·10⁹ additions a
//! rotation, and nearly all of them are spent on translations that score
//! nowhere near the peaks.
//!
//! This module finds exactly the same peaks, in the same order, by the
//! *multi-resolution branch and bound* of E. Olson, *Real-time correlative
//! scan matching* (ICRA 2009), as W. Hess, D. Kohler, H. Rapp and
//! D. Andor use it in Cartographer (*Real-time loop closure in 2D LIDAR
//! SLAM*, ICRA 2016):
//!
//! 1. **Max images.** For a block of `s × s` translations starting at
//!    `c`, each wall `w` of B can at best land on the largest of A's cell
//!    scores in the `s × s` window starting at `w + c`. Summing those
//!    maxima over B's walls bounds the first sum of *every* translation in
//!    the block from above. So for each level `s = 1, 2, 4, …` the image
//!    `M_s(x) = max A(x + d), d ∈ [0, s)²` is computed once (each level
//!    from the one below, four lookups a cell; a window that reaches
//!    outside the raster includes its 0). The second sum is bounded the
//!    same way, with B's scores turned by 180° (so that `w − t` becomes a
//!    window too) and A's walls. The two sums are bounded *separately* and
//!    added: the bound is loose where B's walls want one translation and
//!    A's another, but never too low, and the free space's negative scores
//!    need no special care (a window's maximum is never below any of its
//!    cells).
//! 2. **Best first.** The translations are tiled by blocks of the
//!    coarsest level; a priority queue holds blocks by their bound and
//!    single translations by their exact score (a bound at `s = 1`). The
//!    top entry is taken: a block is split into its four children, whose
//!    bounds go back into the queue; a single translation has, at that
//!    moment, a score no unopened block can beat. So translations come out
//!    exactly in the order the exhaustive search sorts them: score
//!    descending, then row, then column (a block is opened before a
//!    translation of the same value, and translations of equal score come
//!    out by position).
//! 3. **The peak rule, exactly.** Each translation taken is kept if it is a
//!    local maximum by [`Correlation::peaks`]'s rule (no neighbour higher,
//!    no earlier neighbour in row order equal; its neighbours' exact scores
//!    are computed when needed) and lies `apart` from every peak already
//!    kept. Once a peak is kept, every block lying wholly within `apart`
//!    of it is dropped unopened: whatever it holds would be refused. The
//!    search stops when `count` peaks are kept or the best bound left is
//!    not positive (only positive maxima count).
//!
//! The queue and the peaks kept are all the search's state, so it can stop
//! between two entries and go on later: [`PeakSearch::run`] does about as
//! many pyramid lookups as it is given, and the map search takes one
//! rotation's search in such pieces so that the page can draw between
//! them ([`super::mapsearch::MapSearchSteps`]).
//!
//! Each bound costs one lookup per wall cell of both maps (long runs of
//! neighbouring wall cells are added as slices, `Points`), so the saving
//! depends on how fast the bounds fall below the peaks kept; BENCHMARKS.md
//! ("Many robots") has the figures. The answer does not depend on it: the test module checks it
//! against the exhaustive correlation.
//!
//! [`Correlation::peaks`]: super::raster_correlation::Correlation::peaks

use std::collections::{BinaryHeap, HashMap};

/// A raster of cell scores and its wall cells, as the map search draws
/// it: `score[y * width + x]`, walls as `[x, y]`.
#[derive(Clone, Copy, Debug)]
pub struct ScoreImage<'a> {
    pub width: usize,
    pub height: usize,
    pub score: &'a [i32],
    pub walls: &'a [[usize; 2]],
}

/// The max images `M_{2^k}` of one score image, `k = 0, 1, …`: level `k`
/// covers `x ∈ [−(2^k − 1), width)` (and the same in y), stored shifted
/// by `2^k − 1`, row by row; and the same images transposed (stored
/// column by column), so that a run of wall cells down a column is read
/// as one contiguous slice too (`Points`). A window is a square, so the
/// transposed max image is the max image of the transposed scores. The
/// transposed copy is built only for a search that reads it (walls drawn
/// turned have no long column runs). (The default is empty: a
/// placeholder.)
#[derive(Default)]
pub struct MaxPyramid {
    width: usize,
    height: usize,
    levels: Vec<Vec<i8>>,
    transposed: Vec<Vec<i8>>,
}

impl MaxPyramid {
    /// Level 0 from `cell(x, y)`; `None` when a score does not fit a byte.
    pub fn new(
        width: usize,
        height: usize,
        cell: impl Fn(usize, usize) -> i32,
    ) -> Option<MaxPyramid> {
        let mut base = Vec::with_capacity(width * height);
        for y in 0..height {
            for x in 0..width {
                base.push(i8::try_from(cell(x, y)).ok()?);
            }
        }
        Some(MaxPyramid {
            width,
            height,
            levels: vec![base],
            transposed: Vec::new(),
        })
    }

    /// Builds the levels up to `top`, and their transposed copies when
    /// `transposed`.
    fn ensure(&mut self, top: usize, transposed: bool) {
        while self.levels.len() <= top {
            let k = self.levels.len();
            let next = next_level(&self.levels[k - 1], self.width, self.height, k);
            self.levels.push(next);
        }
        if !transposed {
            return;
        }
        if self.transposed.is_empty() {
            let (width, height) = (self.width, self.height);
            let mut base = vec![0i8; width * height];
            for (y, row) in self.levels[0].chunks_exact(width.max(1)).enumerate() {
                for (x, &v) in row.iter().enumerate() {
                    base[x * height + y] = v;
                }
            }
            self.transposed.push(base);
        }
        while self.transposed.len() <= top {
            let k = self.transposed.len();
            let next = next_level(&self.transposed[k - 1], self.height, self.width, k);
            self.transposed.push(next);
        }
    }
}

/// Level `k` of a max image `width × height` from level `k − 1`
/// (`h = 2^(k−1)`): `M_{2h}(x) = max` of `M_h` at `x` and `x + h` in each
/// axis, which in the shifted storage is index `j` and `j − h`.
fn next_level(prev: &[i8], width: usize, height: usize, k: usize) -> Vec<i8> {
    let half = 1usize << (k - 1);
    let (pw, ph) = (width + half - 1, height + half - 1);
    let (lw, lh) = (pw + half, ph + half);
    let pick = |row: &[i8], j: usize| -> i8 {
        let a = if j >= half { row[j - half] } else { 0 };
        let b = if j < row.len() { row[j] } else { 0 };
        a.max(b)
    };
    let mut wide = vec![0i8; lw * ph];
    for y in 0..ph {
        let src = &prev[y * pw..][..pw];
        for (j, d) in wide[y * lw..][..lw].iter_mut().enumerate() {
            *d = pick(src, j);
        }
    }
    let mut next = vec![0i8; lw * lh];
    for (j, row) in next.chunks_exact_mut(lw).enumerate() {
        let upper = (j >= half).then(|| &wide[(j - half) * lw..][..lw]);
        let lower = (j < ph).then(|| &wide[j * lw..][..lw]);
        for (x, d) in row.iter_mut().enumerate() {
            let a = upper.map_or(0, |r| r[x]);
            let b = lower.map_or(0, |r| r[x]);
            *d = a.max(b);
        }
    }
    next
}

/// Points (translation-index offsets) as runs of neighbours. `Σ_p M(c +
/// p)` over a run is a sum over a contiguous slice of the level, which the
/// compiler turns into vector additions: a wall along the raster's rows is
/// one run a row. A wall cell in a run down its column of at least
/// [`MIN_RUN`] cells, longer than its run along its row, joins a column
/// run, read along a row of the transposed level; every other cell is
/// read along its row, in a run when that is at least [`MIN_RUN`] long,
/// else on its own. Walls that cross the raster's axes at an angle are
/// staircases of short steps, read cell by cell as before. The sum is the
/// same integer however the points are grouped.
struct Points {
    /// Row runs, by row.
    rows: Runs,
    /// Column runs, with x and y swapped (rows of the transpose).
    cols: Runs,
    /// How many points (each a lookup of the exhaustive sum).
    count: usize,
}

/// Runs of consecutive points along rows: (row offset, range of `runs`,
/// range of `singles`), rows ascending; each run (first column offset,
/// length) of at least [`MIN_RUN`] points, and the points of shorter runs
/// one by one (column offsets), both ascending.
#[derive(Default)]
struct Runs {
    rows: Vec<(i64, std::ops::Range<usize>, std::ops::Range<usize>)>,
    runs: Vec<(i64, i64)>,
    singles: Vec<i64>,
}

/// Points in a run shorter than this are summed one by one: a slice's
/// set-up costs more than it saves on a staircase of short steps (walls
/// drawn turned). Chosen on `examples/bench_peaks.rs`: at 6 or 12, walls
/// turned 23° or 45° took up to 1.45× as long as cell by cell; at 24 they
/// take as long (within 6 %), and walls along the axes 3–4× less.
const MIN_RUN: i64 = 24;

impl Runs {
    /// From points sorted by row, then column.
    fn new(points: &[[i64; 2]]) -> Runs {
        let mut out = Runs::default();
        let mut i = 0;
        while i < points.len() {
            let y = points[i][1];
            let (r0, s0) = (out.runs.len(), out.singles.len());
            while i < points.len() && points[i][1] == y {
                // The run starting at point i.
                let mut j = i + 1;
                while j < points.len() && points[j][1] == y && points[j][0] == points[j - 1][0] + 1
                {
                    j += 1;
                }
                let len = (j - i) as i64;
                if len >= MIN_RUN {
                    out.runs.push((points[i][0], len));
                } else {
                    out.singles.extend(points[i..j].iter().map(|p| p[0]));
                }
                i = j;
            }
            out.rows
                .push((y, r0..out.runs.len(), s0..out.singles.len()));
        }
        out
    }

    /// `Σ M(c + p)` over the points, `level` being `lw` wide and `lh` high
    /// (0 outside).
    fn sum(&self, level: &[i8], lw: usize, lh: i64, cx: i64, cy: i64) -> i32 {
        let mut sum = 0i32;
        for (py, runs, singles) in &self.rows {
            let y = cy + py;
            if y < 0 || y >= lh {
                continue;
            }
            let row = &level[y as usize * lw..][..lw];
            for &(px, len) in &self.runs[runs.clone()] {
                let lo = (cx + px).max(0);
                let hi = (cx + px + len).min(lw as i64);
                if lo < hi {
                    sum += row[lo as usize..hi as usize]
                        .iter()
                        .map(|&v| v as i32)
                        .sum::<i32>();
                }
            }
            let xs = &self.singles[singles.clone()];
            let Some((&first, &last)) = xs.first().zip(xs.last()) else {
                continue;
            };
            // Columns inside the level: 0 <= cx + px < lw. Most rows lie
            // wholly inside (xs ascend: the first and last tell); only the
            // others need the two binary searches.
            let xs = if cx + first >= 0 && cx + last < lw as i64 {
                xs
            } else {
                let lo = xs.partition_point(|&px| cx + px < 0);
                let hi = xs.partition_point(|&px| cx + px < lw as i64);
                &xs[lo..hi.max(lo)]
            };
            for &px in xs {
                sum += row[(cx + px) as usize] as i32;
            }
        }
        sum
    }
}

impl Points {
    fn new(mut points: Vec<[i64; 2]>) -> Points {
        let count = points.len();
        // Each point's run length along its row, then down its column.
        let along = |points: &mut Vec<[i64; 2]>, axis: usize| -> HashMap<[i64; 2], i64> {
            let other = 1 - axis;
            points.sort_unstable_by_key(|p| (p[other], p[axis]));
            let mut length = HashMap::with_capacity(points.len());
            let mut start = 0;
            for i in 1..=points.len() {
                let breaks = i == points.len()
                    || points[i][other] != points[i - 1][other]
                    || points[i][axis] != points[i - 1][axis] + 1;
                if breaks {
                    for p in &points[start..i] {
                        length.insert(*p, (i - start) as i64);
                    }
                    start = i;
                }
            }
            length
        };
        let down = along(&mut points, 1);
        let across = along(&mut points, 0);
        // `points` is now sorted by row, then column.
        let (in_rows, in_cols): (Vec<[i64; 2]>, Vec<[i64; 2]>) = points
            .iter()
            .copied()
            .partition(|p| down[p] < MIN_RUN || across[p] >= down[p]);
        let mut swapped: Vec<[i64; 2]> = in_cols.iter().map(|p| [p[1], p[0]]).collect();
        swapped.sort_unstable_by_key(|p| (p[1], p[0]));
        Points {
            rows: Runs::new(&in_rows),
            cols: Runs::new(&swapped),
            count,
        }
    }

    /// `Σ_p M_{2^k}(c + p)` (0 outside the level), the bound of the
    /// block of translations starting at `c` (the exact sum at level 0).
    fn bound(&self, pyramid: &MaxPyramid, k: usize, c: [i64; 2]) -> i32 {
        let shift = (1i64 << k) - 1;
        let lw = pyramid.width as i64 + shift;
        let lh = pyramid.height as i64 + shift;
        let (cx, cy) = (c[0] + shift, c[1] + shift);
        let rows = self.rows.sum(&pyramid.levels[k], lw as usize, lh, cx, cy);
        if self.cols.rows.is_empty() {
            return rows;
        }
        rows + self
            .cols
            .sum(&pyramid.transposed[k], lh as usize, lw, cy, cx)
    }
}

/// An entry of the queue: a block of `2^level` translations a side (or
/// one translation, `level` 0) and its bound (exact at level 0). The
/// largest value comes first; at equal values blocks before single
/// translations, and single translations by row, then column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Entry {
    value: i32,
    level: usize,
    /// Block index at its level (translation index at level 0): [x, y].
    at: [i64; 2],
}

impl Ord for Entry {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.value
            .cmp(&o.value)
            .then((self.level > 0).cmp(&(o.level > 0)))
            .then(o.at[1].cmp(&self.at[1]))
            .then(o.at[0].cmp(&self.at[0]))
            .then(self.level.cmp(&o.level))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}

/// The search over translation indices `i ∈ [0, nx) × [0, ny)`: the
/// score's two sums, each a point set over a pyramid (A's, passed in by
/// the caller, who keeps it across B's rotations; B's turned, owned).
struct Search {
    b_max: MaxPyramid,
    /// B's walls over A's pyramid, and A's walls over B's.
    on_a: Points,
    on_b: Points,
    nx: i64,
    ny: i64,
    exact: HashMap<[i64; 2], i32>,
    /// Pyramid lookups so far: the measure of work done.
    lookups: u64,
}

impl Search {
    fn bound(&mut self, a_max: &MaxPyramid, k: usize, c: [i64; 2]) -> i32 {
        self.lookups += (self.on_a.count + self.on_b.count) as u64;
        self.on_a.bound(a_max, k, c) + self.on_b.bound(&self.b_max, k, c)
    }

    fn score(&mut self, a_max: &MaxPyramid, i: [i64; 2]) -> i32 {
        if let Some(&v) = self.exact.get(&i) {
            return v;
        }
        let v = self.bound(a_max, 0, i);
        self.exact.insert(i, v);
        v
    }

    /// [`super::raster_correlation::Correlation::peaks`]'s local maximum rule.
    fn is_local_max(&mut self, a_max: &MaxPyramid, i: [i64; 2], v: i32) -> bool {
        for dy in 0..3 {
            for dx in 0..3 {
                if (dy, dx) == (1, 1) {
                    continue;
                }
                let w = self.score(a_max, [i[0] + dx - 1, i[1] + dy - 1]);
                if !(w < v || (w == v && (dy, dx) >= (1, 1))) {
                    return false;
                }
            }
        }
        true
    }
}

/// Whether every translation of the block (level `k`, index `b`) lies
/// within `apart` of `peak` (all indices).
fn block_within(k: usize, b: [i64; 2], peak: [i64; 2], apart: f64) -> bool {
    let s = 1i64 << k;
    let far = |lo: i64, p: i64| (p - lo).abs().max((lo + s - 1 - p).abs());
    let (dx, dy) = (far(b[0] * s, peak[0]), far(b[1] * s, peak[1]));
    (dx as f64).hypot(dy as f64) < apart
}

/// Whether `i` is refused for lying near a peak kept: written as the
/// negation of [`super::raster_correlation::Correlation::peaks`]'s own test, so
/// that even a NaN `apart` is treated alike.
fn near(i: [i64; 2], peaks: &[([i64; 2], i32)], apart: f64) -> bool {
    !peaks.iter().all(|(u, _)| {
        let (dx, dy) = ((u[0] - i[0]) as f64, (u[1] - i[1]) as f64);
        dx.hypot(dy) >= apart
    })
}

/// A score image's [`MaxPyramid`] (`None` when a score does not fit a
/// byte).
pub fn pyramid_of(image: &ScoreImage) -> Option<MaxPyramid> {
    MaxPyramid::new(image.width, image.height, |x, y| {
        image.score[y * image.width + x]
    })
}

/// [`best_translations`] a piece at a time: the search's queue and the
/// peaks kept so far live here between calls of [`PeakSearch::run`], so a
/// caller with a page to draw can stop after a bounded amount of work and
/// go on later. The peaks do not depend on how the work is cut.
pub struct PeakSearch {
    search: Search,
    queue: BinaryHeap<Entry>,
    out: Vec<([i64; 2], i32)>,
    count: usize,
    apart: f64,
}

impl PeakSearch {
    /// The search of B's raster over A's for the best `count` positive
    /// local maxima at least `apart` apart (see [`best_translations`]),
    /// with the coarsest level's blocks queued. `a_max` is A's pyramid
    /// ([`pyramid_of`]), the same one on every [`PeakSearch::run`]. `None`
    /// when one of B's scores does not fit a byte.
    pub fn new(
        a: ScoreImage,
        a_max: &mut MaxPyramid,
        b: ScoreImage,
        count: usize,
        apart: f64,
    ) -> Option<PeakSearch> {
        let nx = (a.width + b.width - 1) as i64;
        let ny = (a.height + b.height - 1) as i64;
        // The coarsest level tiles the translations with about 8 × 8 blocks.
        let top =
            (64 - ((nx.max(ny) - 1).max(0) as u64).leading_zeros() as usize).saturating_sub(3);
        // B turned by 180°, so that A's wall l meets B's cell i − l as a
        // window of translations too.
        let (bw, bh) = (b.width, b.height);
        let b_max = MaxPyramid::new(bw, bh, |x, y| b.score[(bh - 1 - y) * bw + bw - 1 - x])?;
        let mut queue = BinaryHeap::new();
        let trivial = count == 0 || nx < 3 || ny < 3;
        // B's wall l lands on A's cell i + l − (b.size − 1); A's wall l on
        // the turned B's cell i − l.
        let (bw, bh) = (bw as i64, bh as i64);
        let on_a: Vec<[i64; 2]> = b
            .walls
            .iter()
            .map(|&[x, y]| [x as i64 - (bw - 1), y as i64 - (bh - 1)])
            .collect();
        let on_b: Vec<[i64; 2]> = a
            .walls
            .iter()
            .map(|&[x, y]| [-(x as i64), -(y as i64)])
            .collect();
        let mut search = Search {
            b_max,
            on_a: Points::new(on_a),
            on_b: Points::new(on_b),
            nx,
            ny,
            exact: HashMap::new(),
            lookups: 0,
        };
        if !trivial {
            // B's walls read A's pyramid, A's walls B's: each transposed
            // only where column runs read it.
            a_max.ensure(top, !search.on_a.cols.rows.is_empty());
            search.b_max.ensure(top, !search.on_b.cols.rows.is_empty());
            // Step 2 of the module doc begins: the coarsest blocks.
            let s = 1i64 << top;
            for by in 0..(ny + s - 1) / s {
                for bx in 0..(nx + s - 1) / s {
                    let value = search.bound(a_max, top, [bx * s, by * s]);
                    queue.push(Entry {
                        value,
                        level: top,
                        at: [bx, by],
                    });
                }
            }
        }
        Some(PeakSearch {
            search,
            queue,
            out: Vec::new(),
            count,
            apart,
        })
    }

    /// Pyramid lookups made so far (each wall of both maps, per bound).
    pub fn lookups(&self) -> u64 {
        self.search.lookups
    }

    /// Steps 2 and 3 of the module doc until the peaks are found, or until
    /// about `work` more pyramid lookups are made (it stops between two
    /// queue entries); the peaks, as [`best_translations`] returns them,
    /// once found.
    pub fn run(&mut self, a_max: &MaxPyramid, work: u64) -> Option<Vec<([i64; 2], i32)>> {
        let until = self.search.lookups.saturating_add(work);
        let (count, apart) = (self.count, self.apart);
        while self.search.lookups < until {
            let Some(e) = self.queue.pop() else {
                return Some(std::mem::take(&mut self.out));
            };
            if e.value <= 0 || self.out.len() >= count {
                self.queue.clear();
                return Some(std::mem::take(&mut self.out));
            }
            if e.level == 0 {
                let i = e.at;
                if !near(i, &self.out, apart) && self.search.is_local_max(a_max, i, e.value) {
                    self.out.push((i, e.value));
                }
                continue;
            }
            if self
                .out
                .iter()
                .any(|(u, _)| block_within(e.level, e.at, *u, apart))
            {
                continue;
            }
            self.open(a_max, e);
        }
        None
    }

    /// Splits a block into its four children and queues their bounds.
    fn open(&mut self, a_max: &MaxPyramid, e: Entry) {
        let search = &mut self.search;
        let k = e.level - 1;
        let sk = 1i64 << k;
        for cy in 0..2 {
            for cx in 0..2 {
                let at = [e.at[0] * 2 + cx, e.at[1] * 2 + cy];
                let c = [at[0] * sk, at[1] * sk];
                // Only the interior holds candidates (the exhaustive rule
                // skips the accumulator's outer ring).
                if c[0] > search.nx - 2
                    || c[1] > search.ny - 2
                    || c[0] + sk - 1 < 1
                    || c[1] + sk - 1 < 1
                {
                    continue;
                }
                let value = if k == 0 {
                    search.score(a_max, c)
                } else {
                    search.bound(a_max, k, c)
                };
                self.queue.push(Entry {
                    value,
                    level: k,
                    at,
                });
            }
        }
    }
}

/// The best `count` positive local maxima of the correlation of B's
/// raster over A's, at least `apart` translation cells from each other,
/// as (translation index, score): exactly what
/// [`super::raster_correlation::Correlation::peaks`] returns on the exhaustive
/// correlation (indices there are these plus its `t0`). `a_max` is A's
/// pyramid ([`pyramid_of`]), kept by the caller across B's rotations.
/// `None` when one of B's scores does not fit a byte. [`PeakSearch`] run
/// to the end.
pub fn best_translations(
    a: ScoreImage,
    a_max: &mut MaxPyramid,
    b: ScoreImage,
    count: usize,
    apart: f64,
) -> Option<Vec<([i64; 2], i32)>> {
    let mut search = PeakSearch::new(a, a_max, b, count, apart)?;
    Some(search.run(a_max, u64::MAX).unwrap_or_default())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::merge::raster_correlation::Correlation;

    /// The exhaustive correlation, written out plainly from the formula of
    /// the module doc (zero outside the rasters).
    fn exhaustive(
        a: &ScoreImage,
        b: &ScoreImage,
        count: usize,
        apart: f64,
    ) -> Vec<([i64; 2], i32)> {
        let at = |img: &ScoreImage, x: i64, y: i64| {
            if x < 0 || y < 0 || x >= img.width as i64 || y >= img.height as i64 {
                0
            } else {
                img.score[y as usize * img.width + x as usize]
            }
        };
        let (bw, bh) = (b.width as i64, b.height as i64);
        let nx = a.width + b.width - 1;
        let ny = a.height + b.height - 1;
        let mut acc = vec![0i32; nx * ny];
        for iy in 0..ny as i64 {
            for ix in 0..nx as i64 {
                let mut s = 0;
                for &[x, y] in b.walls {
                    s += at(a, ix + x as i64 - (bw - 1), iy + y as i64 - (bh - 1));
                }
                for &[x, y] in a.walls {
                    // B turned by 180°: B(bw − 1 − (i − l)).
                    s += at(b, bw - 1 - (ix - x as i64), bh - 1 - (iy - y as i64));
                }
                acc[iy as usize * nx + ix as usize] = s;
            }
        }
        Correlation {
            t0: [0, 0],
            nx,
            ny,
            acc,
        }
        .peaks(count, apart)
    }

    /// A raster with walls on a lattice of `period` cells (some segments
    /// left out, by `seed`), free cells inside a disc and unknown outside.
    fn raster(
        width: usize,
        height: usize,
        period: usize,
        seed: u64,
        penalty: i32,
    ) -> (Vec<i32>, Vec<[usize; 2]>) {
        let mut rng = crate::rng::Rng::new(seed);
        let mut wall = vec![false; width * height];
        for y in 0..height {
            for x in 0..width {
                let on = x % period == 0 || y % period == 0;
                wall[y * width + x] = on;
            }
        }
        // Open gaps: each lattice segment is kept or not at random.
        for cy in 0..height / period + 1 {
            for cx in 0..width / period + 1 {
                if seed != 0 && rng.next_u64().is_multiple_of(3) {
                    for d in 1..period {
                        let (x, y) = (cx * period + d, cy * period);
                        if x < width && y < height {
                            wall[y * width + x] = false;
                        }
                    }
                }
                if seed != 0 && rng.next_u64().is_multiple_of(3) {
                    for d in 1..period {
                        let (x, y) = (cx * period, cy * period + d);
                        if x < width && y < height {
                            wall[y * width + x] = false;
                        }
                    }
                }
            }
        }
        let (cx, cy, r) = (
            width as f64 / 2.0,
            height as f64 / 2.0,
            width.min(height) as f64 * 0.45,
        );
        let mut score = vec![0; width * height];
        let mut walls = Vec::new();
        for y in 0..height {
            for x in 0..width {
                let inside = (x as f64 - cx).hypot(y as f64 - cy) < r;
                if !inside {
                    continue;
                }
                let near = (y.saturating_sub(1)..(y + 2).min(height)).any(|v| {
                    (x.saturating_sub(1)..(x + 2).min(width)).any(|u| wall[v * width + u])
                });
                score[y * width + x] = if near { 1 } else { -penalty };
                if wall[y * width + x] {
                    walls.push([x, y]);
                }
            }
        }
        (score, walls)
    }

    fn check(
        sizes: [[usize; 2]; 2],
        periods: [usize; 2],
        seed: u64,
        penalty: i32,
        count: usize,
        apart: f64,
    ) -> usize {
        let (sa, wa) = raster(sizes[0][0], sizes[0][1], periods[0], seed, penalty);
        let (sb, wb) = raster(sizes[1][0], sizes[1][1], periods[1], seed * 2, penalty);
        let a = ScoreImage {
            width: sizes[0][0],
            height: sizes[0][1],
            score: &sa,
            walls: &wa,
        };
        let b = ScoreImage {
            width: sizes[1][0],
            height: sizes[1][1],
            score: &sb,
            walls: &wb,
        };
        let want = exhaustive(&a, &b, count, apart);
        let mut a_max = pyramid_of(&a).expect("scores fit a byte");
        let got = best_translations(a, &mut a_max, b, count, apart).expect("scores fit a byte");
        assert_eq!(got, want, "sizes {sizes:?} periods {periods:?} seed {seed}");
        // The pyramid kept for the next rotation gives the same again.
        assert_eq!(
            best_translations(a, &mut a_max, b, count, apart),
            Some(want.clone())
        );
        // Cut into pieces of a few bounds each, the same peaks.
        let mut piecewise = PeakSearch::new(a, &mut a_max, b, count, apart).expect("fits");
        let piece = (wa.len() + wb.len()) as u64 * 3;
        let mut pieces = 1;
        let got = loop {
            match piecewise.run(&a_max, piece) {
                Some(peaks) => break peaks,
                None => pieces += 1,
            }
        };
        assert_eq!(got, want, "in {pieces} pieces");
        assert!(
            want.is_empty() || pieces > 3,
            "the work is cut: {pieces} pieces"
        );
        want.len()
    }

    #[test]
    fn the_same_peaks_as_the_exhaustive_correlation() {
        let mut found = 0;
        // Lattices (many equal scores: plateaus and ties by position),
        // different sizes and shapes, one map much larger than the other.
        found += check([[40, 30], [25, 35]], [6, 6], 1, 3, 4, 10.0);
        found += check([[60, 50], [50, 60]], [5, 7], 2, 3, 6, 4.5);
        found += check([[90, 70], [30, 20]], [8, 8], 3, 1, 4, 10.0);
        found += check([[17, 90], [80, 12]], [4, 9], 4, 5, 12, 2.0);
        found += check([[33, 33], [33, 33]], [11, 11], 5, 3, 3, 0.5);
        // Whole lattices, symmetric discs: peaks of equal score in one row,
        // taken in row order (the count and the spacing decide which).
        found += check([[41, 41], [41, 41]], [8, 8], 0, 3, 5, 3.0);
        found += check([[45, 37], [29, 29]], [7, 7], 0, 2, 7, 9.0);
        assert!(found >= 25, "{found} peaks");
    }

    #[test]
    fn run_sums_equal_the_sums_point_by_point() {
        // A lattice without gaps in a disc: long runs along rows and down
        // columns, short ones where the lines meet the disc's edge.
        let (sa, wa) = raster(90, 80, 9, 0, 2);
        let a = ScoreImage {
            width: 90,
            height: 80,
            score: &sa,
            walls: &wa,
        };
        let mut m = pyramid_of(&a).expect("fits");
        m.ensure(5, true);
        let points: Vec<[i64; 2]> = wa
            .iter()
            .map(|&[x, y]| [x as i64 - 40, y as i64 - 30])
            .collect();
        let p = Points::new(points.clone());
        assert!(!p.rows.runs.is_empty(), "row runs");
        assert!(!p.cols.runs.is_empty(), "column runs");
        assert!(!p.rows.singles.is_empty(), "cells read one by one");
        assert_eq!(p.count, points.len());
        for k in 0..=5 {
            let shift = (1i64 << k) - 1;
            let (lw, lh) = (90 + shift, 80 + shift);
            for c in [[0, 0], [13, -7], [-50, 20], [70, 75], [-100, 0], [40, 30]] {
                let naive: i32 = points
                    .iter()
                    .map(|q| {
                        let (x, y) = (c[0] + q[0] + shift, c[1] + q[1] + shift);
                        if x < 0 || y < 0 || x >= lw || y >= lh {
                            0
                        } else {
                            m.levels[k][(y * lw + x) as usize] as i32
                        }
                    })
                    .sum();
                assert_eq!(p.bound(&m, k, c), naive, "level {k} at {c:?}");
            }
        }
    }

    #[test]
    fn degenerate_inputs() {
        // Nothing to find: no walls (every sum 0, no positive peak), a
        // single cell (no interior translation), no peaks asked for.
        let (sa, _) = raster(10, 10, 3, 7, 3);
        let bare = ScoreImage {
            width: 10,
            height: 10,
            score: &sa,
            walls: &[],
        };
        let mut m = pyramid_of(&bare).expect("fits");
        assert_eq!(
            best_translations(bare, &mut m, bare, 4, 1.0),
            Some(Vec::new())
        );
        let score = [1];
        let one = ScoreImage {
            width: 1,
            height: 1,
            score: &score,
            walls: &[[0, 0]],
        };
        let mut m = pyramid_of(&one).expect("fits");
        assert_eq!(
            best_translations(one, &mut m, one, 4, 1.0),
            Some(Vec::new())
        );
        assert_eq!(check([[20, 20], [20, 20]], [5, 5], 8, 3, 0, 1.0), 0);
        // Scores beyond a byte are refused, not clamped.
        let big = [-300];
        let wide = ScoreImage {
            width: 1,
            height: 1,
            score: &big,
            walls: &[],
        };
        assert!(pyramid_of(&wide).is_none());
    }
}
