//! # The pose graph and its sparse least-squares optimisation
//!
//! Graph-based SLAM (Lu and Milios, "Globally consistent range scan
//! alignment for environment mapping", Autonomous Robots 4, 1997; taught in
//! G. Grisetti, R. Kümmerle, C. Stachniss, W. Burgard, "A tutorial on
//! graph-based SLAM", IEEE ITS Magazine 2010) keeps one node per key scan,
//! its pose `x_i = (t_i, θ_i)`, and one edge per measured relative pose
//! `z_ij` between two nodes: consecutive key scans (the scan matcher's
//! answer, or odometry where it had none) and loop closures (a scan matched
//! against an old part of the map). The map is then the configuration that
//! disagrees least with every edge:
//!
//! ```text
//! x* = argmin Σ_ij e_ijᵀ Ω_ij e_ij
//! e_ij = ( R_zᵀ (R_iᵀ (t_j − t_i) − t_z),  θ_j − θ_i − θ_z )     (tutorial eq. 30)
//! ```
//!
//! with `Ω_ij` the edge's information (inverse covariance). Gauss–Newton
//! linearises each error around the current poses, `e(x + Δ) ≈ e + A Δ_i
//! + B Δ_j` with
//!
//! ```text
//! A = [ −R_zᵀR_iᵀ   R_zᵀ ∂R_iᵀ/∂θ (t_j − t_i) ]      B = [ R_zᵀR_iᵀ  0 ]
//!     [   0   0          −1                 ]          [   0  0   1 ]
//! ```
//!
//! and solves the normal equations `H Δ = −b`, `H = Σ JᵀΩJ`, `b = Σ JᵀΩe`.
//! `H` is sparse: a 3 × 3 block per node and per edge, nothing else. The
//! first node is held fixed (it defines the frame), so its rows are left
//! out and `H` is positive definite. The system is solved by a sparse
//! Cholesky factorisation with a fill-reducing ordering (the `faer` crate's
//! supernodal LLᵀ with AMD): a trajectory with loop closures factorises in
//! milliseconds where a dense solve of 3n unknowns would take seconds.
//! `H`'s pattern does not change while the poses move, so one optimisation
//! lays out its blocks (`BlockPattern`) and orders its elimination once;
//! each Gauss–Newton step only refills the numbers and factorises them.

use crate::geom::{wrap_angle, Pose2};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Mat, Side};

/// A measured relative pose between two nodes.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Edge {
    pub from: usize,
    pub to: usize,
    /// `x_from⁻¹ ⊕ x_to` as measured.
    pub measurement: Pose2,
    /// Information (inverse covariance) of the error, row-major 3 × 3.
    pub information: [[f64; 3]; 3],
    /// True for loop closures (the consistency check may drop them).
    pub loop_closure: bool,
}

impl Edge {
    /// An edge with diagonal information: standard deviations in metres
    /// (both axes) and radians.
    pub fn new(from: usize, to: usize, measurement: Pose2, sigma_m: f64, sigma_rad: f64) -> Edge {
        let (a, b) = (1.0 / (sigma_m * sigma_m), 1.0 / (sigma_rad * sigma_rad));
        Edge {
            from,
            to,
            measurement,
            information: [[a, 0.0, 0.0], [0.0, a, 0.0], [0.0, 0.0, b]],
            loop_closure: false,
        }
    }
}

/// Nodes (poses) and edges.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PoseGraph {
    #[serde(with = "super::keep_capacity")]
    pub nodes: Vec<Pose2>,
    #[serde(with = "super::keep_capacity")]
    pub edges: Vec<Edge>,
}

/// The error of one edge at the current poses and its Jacobians.
fn linearise(nodes: &[Pose2], e: &Edge) -> ([f64; 3], [[f64; 3]; 3], [[f64; 3]; 3]) {
    let (xi, xj, z) = (nodes[e.from], nodes[e.to], e.measurement);
    let (si, ci) = xi.theta.sin_cos();
    let (sz, cz) = z.theta.sin_cos();
    let (dx, dy) = (xj.x - xi.x, xj.y - xi.y);
    // R_iᵀ (t_j − t_i) and its derivative in θ_i.
    let (lx, ly) = (ci * dx + si * dy, -si * dx + ci * dy);
    let (dlx, dly) = (-si * dx + ci * dy, -ci * dx - si * dy);
    let (ux, uy) = (lx - z.x, ly - z.y);
    let err = [
        cz * ux + sz * uy,
        -sz * ux + cz * uy,
        wrap_angle(xj.theta - xi.theta - z.theta),
    ];
    // R_zᵀ R_iᵀ = rotation by −(θ_i + θ_z).
    let (s, c) = (xi.theta + z.theta).sin_cos();
    let a = [
        [-c, -s, cz * dlx + sz * dly],
        [s, -c, -sz * dlx + cz * dly],
        [0.0, 0.0, -1.0],
    ];
    let b = [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]];
    (err, a, b)
}

/// The information of edge `e` in one Gauss–Newton step: as measured, or
/// for a loop closure under Dynamic Covariance Scaling with `phi`, scaled
/// by `s² = min(1, 2Φ / (Φ + χ²))²` (Agarwal et al. 2013, eq. 15).
fn dcs_information(e: &Edge, err: &[f64; 3], phi: Option<f64>) -> [[f64; 3]; 3] {
    let mut w = e.information;
    let Some(phi) = phi.filter(|_| e.loop_closure) else {
        return w;
    };
    let chi2: f64 = (0..3)
        .map(|r| (0..3).map(|c| err[r] * w[r][c] * err[c]).sum::<f64>())
        .sum();
    let s = (2.0 * phi / (phi + chi2)).min(1.0);
    for row in &mut w {
        for v in row.iter_mut() {
            *v *= s * s;
        }
    }
    w
}

fn mul_t(a: &[[f64; 3]; 3], w: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut out = [[0.0; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            let mut s = 0.0;
            for k in 0..3 {
                for l in 0..3 {
                    s += a[k][r] * w[k][l] * b[l][c];
                }
            }
            out[r][c] = s;
        }
    }
    out
}

impl PoseGraph {
    /// `e_ijᵀ Ω_ij e_ij` of one edge at the current poses.
    pub fn chi2(&self, edge: &Edge) -> f64 {
        let (e, ..) = linearise(&self.nodes, edge);
        let w = &edge.information;
        (0..3)
            .map(|r| (0..3).map(|c| e[r] * w[r][c] * e[c]).sum::<f64>())
            .sum()
    }

    /// Sum of [`PoseGraph::chi2`] over all edges.
    pub fn total_chi2(&self) -> f64 {
        self.edges.iter().map(|e| self.chi2(e)).sum()
    }

    /// Runs up to `iterations` Gauss–Newton steps (node 0 fixed); stops
    /// when a step moves no pose by more than 1e-6. Returns the number of
    /// steps taken, or an error if the system is singular (a node without
    /// any edge).
    pub fn optimise(&mut self, iterations: usize) -> Result<usize, String> {
        self.optimise_robust(iterations, None)
    }

    /// Adds loop-closure `edges`, optimises (`iterations`, Dynamic
    /// Covariance Scaling with `phi`), and keeps them only if every one is
    /// then satisfied within `max_chi2`; otherwise puts the nodes and edges
    /// back as they were. Returns whether they were kept.
    pub fn try_closures(
        &mut self,
        edges: &[Edge],
        iterations: usize,
        phi: Option<f64>,
        max_chi2: f64,
    ) -> bool {
        let saved_nodes = self.nodes.clone();
        let saved_edges = self.edges.len();
        self.edges.extend_from_slice(edges);
        let ok = self.optimise_robust(iterations, phi).is_ok()
            && edges.iter().all(|e| self.chi2(e) <= max_chi2);
        if !ok {
            self.nodes = saved_nodes;
            self.edges.truncate(saved_edges);
        }
        ok
    }

    /// [`PoseGraph::optimise`] with Dynamic Covariance Scaling of the loop
    /// closures when `phi` is given (see the module doc): each step weighs
    /// a closure's information by `s²`, `s = min(1, 2Φ / (Φ + χ²))` at the
    /// current poses.
    pub fn optimise_robust(
        &mut self,
        iterations: usize,
        phi: Option<f64>,
    ) -> Result<usize, String> {
        let n = self.nodes.len();
        if n < 2 {
            return Ok(0);
        }
        // `H`'s pattern (a block per node and per edge) is the same at every
        // step: its blocks' places, and its symbolic factorisation (the AMD
        // ordering and the elimination tree), are made once, and each step
        // only fills in and factorises the numbers.
        let pattern = BlockPattern::new(n, &self.edges);
        let symbolic = SymbolicLlt::try_new(pattern.symbolic.as_ref(), Side::Lower)
            .map_err(|e| format!("pose graph: {e:?}"))?;
        let mut values = Vec::with_capacity(pattern.symbolic.row_idx().len());
        for it in 0..iterations {
            let (h, b) = self.normal_equations(&pattern, phi);
            pattern.column_major(&h, &mut values);
            let m = SparseColMatRef::new(pattern.symbolic.as_ref(), &values);
            let llt = Llt::try_new_with_symbolic(symbolic.clone(), m, Side::Lower)
                .map_err(|e| format!("pose graph is not positive definite: {e:?}"))?;
            let mut rhs = Mat::<f64>::from_fn(b.len(), 1, |r, _| -b[r]);
            llt.solve_in_place(rhs.as_mut());
            let mut largest = 0f64;
            for k in 1..n {
                let d = [
                    rhs[(3 * (k - 1), 0)],
                    rhs[(3 * (k - 1) + 1, 0)],
                    rhs[(3 * (k - 1) + 2, 0)],
                ];
                let p = &mut self.nodes[k];
                *p = Pose2::new(p.x + d[0], p.y + d[1], wrap_angle(p.theta + d[2]));
                largest = largest.max(d[0].abs()).max(d[1].abs()).max(d[2].abs());
            }
            if !largest.is_finite() {
                return Err("pose graph optimisation diverged".into());
            }
            if largest < 1e-6 {
                return Ok(it + 1);
            }
        }
        Ok(iterations)
    }

    /// `H`'s 3 × 3 blocks in `pattern`'s order (lower triangle, unknown
    /// `k − 1` for node `k`) and `b`.
    fn normal_equations(
        &self,
        pattern: &BlockPattern,
        phi: Option<f64>,
    ) -> (Vec<[[f64; 3]; 3]>, Vec<f64>) {
        let n = self.nodes.len();
        let mut h = vec![[[0.0; 3]; 3]; pattern.blocks.len()];
        let mut b = vec![0.0; 3 * (n - 1)];
        // A tiny diagonal keeps a node that only the fixed one constrains
        // in one direction from making H singular; it moves nothing.
        for &slot in &pattern.diagonal {
            for (d, row) in h[slot].iter_mut().enumerate() {
                row[d] += 1e-9;
            }
        }
        for (e, slots) in self.edges.iter().zip(&pattern.edge_slots) {
            let (err, ja, jb) = linearise(&self.nodes, e);
            let w = &dcs_information(e, &err, phi);
            let parts = [(e.from, ja), (e.to, jb)];
            for (pi, &(p, jp)) in parts.iter().enumerate() {
                if p == 0 {
                    continue;
                }
                let ip = p - 1;
                // b_p += J_pᵀ Ω e
                for r in 0..3 {
                    let mut s = 0.0;
                    for k in 0..3 {
                        for l in 0..3 {
                            s += jp[k][r] * w[k][l] * err[l];
                        }
                    }
                    b[3 * ip + r] += s;
                }
                for (qi, &(_, jq)) in parts.iter().enumerate() {
                    let Some(slot) = slots[pi][qi] else {
                        continue;
                    };
                    let blk = mul_t(&jp, w, &jq);
                    let acc = &mut h[slot];
                    for r in 0..3 {
                        for c in 0..3 {
                            acc[r][c] += blk[r][c];
                        }
                    }
                }
            }
        }
        (h, b)
    }
}

/// Where `H`'s 3 × 3 blocks lie, for one set of nodes and edges: the blocks
/// of its lower triangle (unknown `k − 1` for node `k`; node 0 is fixed),
/// column by column, and the column-compressed pattern of their entries
/// that the sparse Cholesky factorisation reads.
struct BlockPattern {
    /// `(column block, row block)` of each block, sorted: column-major,
    /// rows ascending within a column.
    blocks: Vec<(usize, usize)>,
    /// Where each block column's blocks begin in `blocks` (one more entry
    /// than there are columns).
    column_start: Vec<usize>,
    /// The slot of each unknown's diagonal block.
    diagonal: Vec<usize>,
    /// Per edge, the slot of block `(p, q)` for `p`, `q` its `from` (0) and
    /// `to` (1); `None` where one is the fixed node or `q`'s node comes
    /// after `p`'s (the upper triangle).
    edge_slots: Vec<[[Option<usize>; 2]; 2]>,
    /// Every entry of every block, column by column.
    symbolic: SymbolicSparseColMat<usize>,
}

impl BlockPattern {
    fn new(n: usize, edges: &[Edge]) -> BlockPattern {
        let lower = |p: usize, q: usize| (p != 0 && q != 0 && q <= p).then(|| (q - 1, p - 1));
        let mut blocks: Vec<(usize, usize)> = (0..n - 1).map(|k| (k, k)).collect();
        for e in edges {
            for p in [e.from, e.to] {
                blocks.extend([e.from, e.to].into_iter().filter_map(|q| lower(p, q)));
            }
        }
        blocks.sort_unstable();
        blocks.dedup();
        let slot = |key: (usize, usize)| blocks.binary_search(&key).ok();
        let diagonal = (0..n - 1).filter_map(|k| slot((k, k))).collect();
        let edge_slots = edges
            .iter()
            .map(|e| {
                let ends = [e.from, e.to];
                ends.map(|p| ends.map(|q| lower(p, q).and_then(slot)))
            })
            .collect();
        let mut column_start = Vec::with_capacity(n);
        let mut col_ptr = Vec::with_capacity(3 * (n - 1) + 1);
        let mut row_idx = Vec::with_capacity(9 * blocks.len());
        col_ptr.push(0);
        let mut next = 0;
        for c in 0..n - 1 {
            column_start.push(next);
            let run = blocks[next..]
                .iter()
                .take_while(|&&(col, _)| col == c)
                .count();
            for _ in 0..3 {
                for &(_, r) in &blocks[next..next + run] {
                    row_idx.extend(3 * r..3 * r + 3);
                }
                col_ptr.push(row_idx.len());
            }
            next += run;
        }
        column_start.push(next);
        let dim = 3 * (n - 1);
        BlockPattern {
            symbolic: SymbolicSparseColMat::new_checked(dim, dim, col_ptr, None, row_idx),
            blocks,
            column_start,
            diagonal,
            edge_slots,
        }
    }

    /// The entries of `h` (blocks in this pattern's order) in the order of
    /// [`BlockPattern::symbolic`], into `values`.
    fn column_major(&self, h: &[[[f64; 3]; 3]], values: &mut Vec<f64>) {
        values.clear();
        for run in self.column_start.windows(2) {
            for c in 0..3 {
                for blk in &h[run[0]..run[1]] {
                    values.extend([blk[0][c], blk[1][c], blk[2][c]]);
                }
            }
        }
    }
}
