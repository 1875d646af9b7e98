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

use crate::geom::{wrap_angle, Pose2};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};
use std::collections::BTreeMap;

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
    #[serde(with = "super::handoff::keep_capacity")]
    pub nodes: Vec<Pose2>,
    #[serde(with = "super::handoff::keep_capacity")]
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
        // step, so its symbolic factorisation (the AMD ordering and the
        // elimination tree) is made once and only the numbers are redone.
        let mut symbolic: Option<SymbolicLlt<usize>> = None;
        for it in 0..iterations {
            let (h, b) = self.normal_equations(phi);
            let dim = 3 * (n - 1);
            let triplets: Vec<Triplet<usize, usize, f64>> = h
                .iter()
                .flat_map(|(&(i, j), blk)| {
                    (0..3).flat_map(move |r| {
                        (0..3).map(move |c| Triplet::new(3 * i + r, 3 * j + c, blk[r][c]))
                    })
                })
                .collect();
            let m = SparseColMat::<usize, f64>::try_new_from_triplets(dim, dim, &triplets)
                .map_err(|e| format!("pose graph: {e:?}"))?;
            let pattern = match &symbolic {
                Some(done) => done.clone(),
                None => {
                    let made = SymbolicLlt::try_new(m.symbolic(), Side::Lower)
                        .map_err(|e| format!("pose graph: {e:?}"))?;
                    symbolic.insert(made).clone()
                }
            };
            let llt = Llt::try_new_with_symbolic(pattern, m.as_ref(), Side::Lower)
                .map_err(|e| format!("pose graph is not positive definite: {e:?}"))?;
            let mut rhs = Mat::<f64>::from_fn(dim, 1, |r, _| -b[r]);
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

    /// `H` as 3 × 3 blocks (lower triangle, unknown `k − 1` for node `k`)
    /// and `b`.
    #[allow(clippy::type_complexity)]
    fn normal_equations(
        &self,
        phi: Option<f64>,
    ) -> (BTreeMap<(usize, usize), [[f64; 3]; 3]>, Vec<f64>) {
        let n = self.nodes.len();
        let mut h: BTreeMap<(usize, usize), [[f64; 3]; 3]> = BTreeMap::new();
        let mut b = vec![0.0; 3 * (n - 1)];
        // A tiny diagonal keeps a node that only the fixed one constrains
        // in one direction from making H singular; it moves nothing.
        for k in 0..n - 1 {
            let blk = h.entry((k, k)).or_insert([[0.0; 3]; 3]);
            for (d, row) in blk.iter_mut().enumerate() {
                row[d] += 1e-9;
            }
        }
        for e in &self.edges {
            let (err, ja, jb) = linearise(&self.nodes, e);
            let w = &dcs_information(e, &err, phi);
            let parts = [(e.from, ja), (e.to, jb)];
            for &(p, jp) in &parts {
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
                for &(q, jq) in &parts {
                    if q == 0 || q > p {
                        continue;
                    }
                    let blk = mul_t(&jp, w, &jq);
                    let acc = h.entry((ip, q - 1)).or_insert([[0.0; 3]; 3]);
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
