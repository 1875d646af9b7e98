//! # Place recognition with a bag of visual words
//!
//! Matching every frame of one robot against every frame of the other
//! (300 × 300 SURF matchings and MSAC fits) would take minutes. Text search
//! has the answer: describe each document by the *words* it contains and
//! compare those summaries. Sivic and Zisserman (*Video Google*, ICCV 2003)
//! carried it over to images, Nistér and Stewénius (*Scalable Recognition
//! with a Vocabulary Tree*, CVPR 2006) made it fast; this file follows both.
//!
//! * **Visual words.** SURF descriptors (64 numbers, unit length) are
//!   clustered by k-means; each cluster is a *word*, and a descriptor is
//!   replaced by the nearest cluster centre. A flat vocabulary of `K` words
//!   costs `K` distance computations per descriptor; a *vocabulary tree*
//!   (hierarchical k-means: `branching` clusters, each split again, `depth`
//!   levels) costs `branching · depth` for `branching^depth` words. Bay et
//!   al.'s sign of the Laplacian (§4.3) splits the descriptors first, for
//!   free: a dark blob and a bright blob never share a word.
//! * **Training** runs k-means++ seeding (Arthur and Vassilvitskii 2007)
//!   then a few Lloyd iterations at every node, on a deterministic subsample
//!   of the robots' own descriptors (an even stride over all of them).
//! * **tf-idf.** A frame's *bag* counts its words (term frequency `tf`),
//!   weighted by how rare each word is among the training frames
//!   (`idf = ln(N / nᵢ)`, `N` frames of which `nᵢ` contain word `i`): a
//!   word on every wall says nothing about *which* wall. Bags are
//!   normalised to unit length and compared by their dot product (the
//!   cosine, 0 for nothing in common, 1 for the same words in the same
//!   proportions).
//! * **Proposals.** Through an inverted file (for each word, the frames of
//!   robot B that contain it) one frame of A is scored against all of B's
//!   in time proportional to the words they share. Each frame of either
//!   robot nominates its `per_frame` best partners; the union, best first,
//!   is cut to `max_pairs`.
//!
//! Similar-looking frames are only *proposals*: repeated textures make
//! different places look alike, so [`super::verify`] checks each
//! geometrically. A bag is made of a frame's strongest keypoints, whether
//! or not the laser reaches them: a wall seen beyond the laser's range can
//! still propose a pair whose nearer keypoints verify.
//!
//! Cost, for 2 × 301 frames of 200-350 keypoints (150 strongest per bag,
//! 512 words): training and all bags about 60-80 ms natively, proposals
//! about 10 ms; in wasm (SIMD128, node) about 70 ms and 35 ms once the
//! engine has optimised the code, two to four times that on a first call.

use crate::surf::prng::SplitMix64;
use crate::surf::simd::dot64_many;
use crate::surf::Features;

/// Settings of [`Vocabulary::train`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VocabularyConfig {
    /// Children per node of the tree (2..=64). Default 16.
    pub branching: usize,
    /// Levels below the Laplacian split. Default 2 (256 words per sign).
    pub depth: usize,
    /// Descriptors sampled for training, at most. Default 5,000: about 20
    /// per word, plenty for centres that only need to split the space.
    pub max_training: usize,
    /// Lloyd iterations per node. Default 4 (the assignments barely change
    /// after that, and a word is a coarse thing).
    pub iterations: usize,
    /// Only the strongest keypoints of a frame (by det(H)) go into its bag.
    /// Default 150.
    pub max_words_per_frame: usize,
}

impl Default for VocabularyConfig {
    fn default() -> Self {
        VocabularyConfig {
            branching: 16,
            depth: 2,
            max_training: 5_000,
            iterations: 4,
            max_words_per_frame: 150,
        }
    }
}

/// One node of the tree: its children (a range of `Vocabulary::nodes`) or,
/// for a leaf, its word.
#[derive(Clone, Debug)]
struct Node {
    first_child: usize,
    children: usize,
    word: usize,
}

/// A trained vocabulary tree with idf weights.
#[derive(Clone, Debug)]
pub struct Vocabulary {
    /// Node 0 is the root of bright blobs (Laplacian −1), node 1 of dark.
    nodes: Vec<Node>,
    /// Centre of each node (the roots' are unused).
    centres: Vec<[f32; 64]>,
    /// `0.5·|c|²` of each centre: `|d − c|² = |d|² − 2(d·c − 0.5|c|²)`.
    half_norm2: Vec<f32>,
    idf: Vec<f32>,
    max_words_per_frame: usize,
}

/// A frame's words: `(word, weight)` sorted by word, unit length.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bag {
    pub words: Vec<(u32, f32)>,
}

impl Bag {
    pub fn is_empty(&self) -> bool {
        self.words.is_empty()
    }
}

/// Squared length of a descriptor (or centre).
fn norm2(a: &[f32; 64]) -> f32 {
    a.iter().map(|v| v * v).sum()
}

/// Index of the centre nearest to `p`: `|p − c|² = |p|² − 2(p·c − ½|c|²)`,
/// so the largest `p·c − ½|c|²` wins. `dots` is scratch of the centres' length.
fn nearest(p: &[f32; 64], centres: &[[f32; 64]], half_norm2: &[f32], dots: &mut [f32]) -> usize {
    dot64_many(p, centres, dots);
    argmax(dots.iter().zip(half_norm2).map(|(d, h)| d - h))
}

/// k-means++ seeding then Lloyd iterations. Returns the centres (at most
/// `k`, fewer when there are fewer distinct points) and each point's
/// nearest centre. (Each pass over the points is a function of its own: a
/// wasm engine optimises a function after a few calls, never a loop that is
/// already running.)
fn kmeans(
    points: &[[f32; 64]],
    k: usize,
    iterations: usize,
    rng: &mut SplitMix64,
) -> (Vec<[f32; 64]>, Vec<usize>) {
    if points.is_empty() || k == 0 {
        return (Vec::new(), Vec::new());
    }
    let norms: Vec<f32> = points.iter().map(norm2).collect();
    let mut dots = vec![0f32; points.len()];
    // Squared distance of every point to its nearest centre so far.
    let mut nearest_d2 = vec![f32::INFINITY; points.len()];
    let first = rng.below(points.len());
    let mut centres: Vec<[f32; 64]> = vec![points[first]];
    seed_distances(points, &norms, first, &mut dots, &mut nearest_d2);
    while centres.len() < k {
        let total: f64 = nearest_d2.iter().map(|&d| d as f64).sum();
        if total <= 1e-9 {
            break; // every point sits on a centre
        }
        // Draw a point with probability proportional to its squared distance.
        let target = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64 * total;
        let Some(pick) = draw(&nearest_d2, target) else {
            break;
        };
        seed_distances(points, &norms, pick, &mut dots, &mut nearest_d2);
        centres.push(points[pick]);
    }
    let mut assign = vec![0usize; points.len()];
    let mut cdots = vec![0f32; centres.len()];
    for it in 0..=iterations {
        let half: Vec<f32> = centres.iter().map(|c| 0.5 * norm2(c)).collect();
        let changed = assign_points(points, &centres, &half, &mut assign, &mut cdots);
        if it == iterations || (!changed && it > 0) {
            break;
        }
        move_centres(points, &assign, &mut centres);
    }
    (centres, assign)
}

/// Lowers every point's distance to its nearest centre with the new centre
/// `points[c]`.
fn seed_distances(
    points: &[[f32; 64]],
    norms: &[f32],
    c: usize,
    dots: &mut [f32],
    nearest_d2: &mut [f32],
) {
    dot64_many(&points[c], points, dots);
    for ((n, &d), &norm) in nearest_d2.iter_mut().zip(dots.iter()).zip(norms) {
        *n = n.min((norm + norms[c] - 2.0 * d).max(0.0));
    }
}

/// The first point at which the running sum of `weights` reaches `target`
/// (the last positive one if rounding leaves it short); `None` when all are
/// zero.
fn draw(weights: &[f32], target: f64) -> Option<usize> {
    let mut acc = 0.0;
    let mut pick = None;
    for (i, &d) in weights.iter().enumerate() {
        acc += d as f64;
        if d > 0.0 {
            pick = Some(i);
            if acc >= target {
                break;
            }
        }
    }
    pick
}

/// Assigns every point to its nearest centre; whether any assignment
/// changed.
fn assign_points(
    points: &[[f32; 64]],
    centres: &[[f32; 64]],
    half_norm2: &[f32],
    assign: &mut [usize],
    dots: &mut [f32],
) -> bool {
    let mut changed = false;
    for (p, a) in points.iter().zip(assign.iter_mut()) {
        let best = nearest(p, centres, half_norm2, dots);
        changed |= best != *a;
        *a = best;
    }
    changed
}

/// Moves every centre to the mean of its points (a centre without points
/// stays where it is).
fn move_centres(points: &[[f32; 64]], assign: &[usize], centres: &mut [[f32; 64]]) {
    let mut sums = vec![[0f64; 64]; centres.len()];
    let mut counts = vec![0usize; centres.len()];
    for (p, &a) in points.iter().zip(assign) {
        counts[a] += 1;
        for (s, v) in sums[a].iter_mut().zip(p) {
            *s += *v as f64;
        }
    }
    for ((c, s), &n) in centres.iter_mut().zip(&sums).zip(&counts) {
        if n > 0 {
            for (cv, sv) in c.iter_mut().zip(s) {
                *cv = (*sv / n as f64) as f32;
            }
        }
    }
}

/// Index of the largest value (the first on ties; 0 when empty).
fn argmax(values: impl Iterator<Item = f32>) -> usize {
    let mut best = (0, f32::NEG_INFINITY);
    for (i, v) in values.enumerate() {
        if v > best.1 {
            best = (i, v);
        }
    }
    best.0
}

/// The strongest `max` keypoints of a frame with a usable descriptor:
/// indices, strongest first.
fn strongest(f: &Features, max: usize) -> Vec<usize> {
    let n = f.keypoints.len().min(f.descriptors.len());
    let mut idx: Vec<usize> = (0..n)
        .filter(|&i| f.descriptors[i].0.iter().any(|&v| v != 0.0))
        .collect();
    idx.sort_by(|&a, &b| {
        f.keypoints[b]
            .response
            .total_cmp(&f.keypoints[a].response)
            .then(a.cmp(&b))
    });
    idx.truncate(max);
    idx
}

impl Vocabulary {
    /// Trains the tree on the frames `sets` (one [`Features`] per frame,
    /// typically every frame of every robot) and weights its words by their
    /// document frequency in those frames. Deterministic for a given `seed`.
    /// With no descriptors at all the vocabulary is empty and every bag is
    /// empty.
    pub fn train(sets: &[&Features], cfg: &VocabularyConfig, seed: u64) -> Vocabulary {
        Self::train_with_bags(sets, cfg, seed).0
    }

    /// [`Vocabulary::train`], also returning the bag of every training frame
    /// (the same as [`Vocabulary::bag`] would give, at no extra cost: the
    /// words are needed for the document frequencies anyway).
    /// [`VocabularyTraining`]'s steps in one call.
    pub fn train_with_bags(
        sets: &[&Features],
        cfg: &VocabularyConfig,
        seed: u64,
    ) -> (Vocabulary, Vec<Bag>) {
        let mut training = VocabularyTraining::new(sets, cfg, seed);
        training.add(sets);
        training.finish()
    }

    /// Builds the subtree under `node` from `points`, `levels` deep.
    fn grow(
        &mut self,
        node: usize,
        points: &[[f32; 64]],
        levels: usize,
        cfg: &VocabularyConfig,
        rng: &mut SplitMix64,
        words: &mut usize,
    ) {
        let branching = cfg.branching.clamp(2, 64);
        let (centres, assign) = if levels == 0 || points.len() < 2 * branching {
            (Vec::new(), Vec::new())
        } else {
            kmeans(points, branching, cfg.iterations, rng)
        };
        if centres.len() < 2 {
            self.nodes[node].word = *words;
            *words += 1;
            return;
        }
        let first = self.nodes.len();
        self.nodes[node].first_child = first;
        self.nodes[node].children = centres.len();
        for c in &centres {
            self.nodes.push(Node {
                first_child: 0,
                children: 0,
                word: 0,
            });
            self.centres.push(*c);
        }
        // Partition the points among the children, then recurse.
        let mut parts: Vec<Vec<[f32; 64]>> = vec![Vec::new(); centres.len()];
        for (p, &a) in points.iter().zip(&assign) {
            parts[a].push(*p);
        }
        for (k, part) in parts.iter().enumerate() {
            self.grow(first + k, part, levels - 1, cfg, rng, words);
        }
    }

    /// Number of words.
    pub fn len(&self) -> usize {
        self.idf.len()
    }

    pub fn is_empty(&self) -> bool {
        self.idf.is_empty()
    }

    /// The word of one descriptor (`None` for an untrained vocabulary).
    pub fn quantise(&self, descriptor: &[f32; 64], laplacian: i8) -> Option<usize> {
        let mut node = usize::from(laplacian > 0);
        let mut dots = [0f32; 64];
        loop {
            let n = self.nodes.get(node)?;
            if n.children == 0 {
                return Some(n.word);
            }
            let range = n.first_child..n.first_child + n.children;
            let out = &mut dots[..n.children.min(64)];
            dot64_many(
                descriptor,
                &self.centres[range.start..range.start + out.len()],
                out,
            );
            let best = argmax(
                out.iter()
                    .zip(&self.half_norm2[range.start..])
                    .map(|(d, h)| d - h),
            );
            node = n.first_child + best;
        }
    }

    /// The words of keypoints `idx` of `f`, sorted.
    fn words_of(&self, f: &Features, idx: &[usize]) -> Vec<u32> {
        let mut words: Vec<u32> = idx
            .iter()
            .filter_map(|&i| self.quantise(&f.descriptors[i].0, f.keypoints[i].laplacian))
            .map(|w| w as u32)
            .collect();
        words.sort_unstable();
        words
    }

    /// tf-idf weights of sorted `words` out of `total` keypoints, unit
    /// length.
    fn weigh(&self, words: &[u32], total: usize) -> Bag {
        let mut counts: Vec<(u32, f32)> = Vec::new();
        for &w in words.iter().filter(|&&w| (w as usize) < self.idf.len()) {
            match counts.last_mut() {
                Some((lw, c)) if *lw == w => *c += 1.0,
                _ => counts.push((w, 1.0)),
            }
        }
        let total = total.max(1) as f32;
        for (w, c) in counts.iter_mut() {
            *c = *c / total * self.idf[*w as usize];
        }
        counts.retain(|(_, v)| *v > 0.0);
        let norm = counts.iter().map(|(_, v)| v * v).sum::<f32>().sqrt();
        if norm > 0.0 {
            counts.iter_mut().for_each(|(_, v)| *v /= norm);
        }
        Bag { words: counts }
    }

    /// A frame's bag of words: tf-idf weights of its strongest keypoints'
    /// words, unit length (empty for a frame without features, or when
    /// every word it has is on every training frame).
    pub fn bag(&self, f: &Features) -> Bag {
        let idx = strongest(f, self.max_words_per_frame);
        self.weigh(&self.words_of(f, &idx), idx.len())
    }
}

/// [`Vocabulary::train_with_bags`] a step at a time, for a caller that
/// cannot wait for all of it (the page's merge): the tree
/// ([`VocabularyTraining::new`], k-means on a subsample), then the words of
/// the training frames a batch at a time ([`VocabularyTraining::add`], one
/// robot's frames say: quantising every frame is most of the work), then
/// the idf weights and every frame's bag ([`VocabularyTraining::finish`]).
pub struct VocabularyTraining {
    /// The tree, its idf not yet known.
    vocab: Vocabulary,
    /// Document frequency of each word over the frames added so far.
    df: Vec<u32>,
    /// Each added frame's sorted words and its keypoints used, in order.
    frame_words: Vec<(Vec<u32>, usize)>,
}

impl VocabularyTraining {
    /// The tree trained on the frames `sets`, by sign of the Laplacian, on
    /// an even stride over their strongest descriptors. Deterministic for a
    /// given `seed`.
    pub fn new(sets: &[&Features], cfg: &VocabularyConfig, seed: u64) -> VocabularyTraining {
        let per_frame = cfg.max_words_per_frame.max(1);
        let chosen: Vec<Vec<usize>> = sets.iter().map(|f| strongest(f, per_frame)).collect();
        // Descriptors by sign of the Laplacian, an even stride over all.
        let total: usize = chosen.iter().map(Vec::len).sum();
        let stride = total.div_ceil(cfg.max_training.max(1)).max(1);
        let mut pools: [Vec<[f32; 64]>; 2] = [Vec::new(), Vec::new()];
        let mut counter = 0usize;
        for (f, idx) in sets.iter().zip(&chosen) {
            for &i in idx {
                if counter.is_multiple_of(stride) {
                    let sign = usize::from(f.keypoints[i].laplacian > 0);
                    pools[sign].push(f.descriptors[i].0);
                }
                counter += 1;
            }
        }
        let leaf = Node {
            first_child: 0,
            children: 0,
            word: 0,
        };
        let mut vocab = Vocabulary {
            nodes: vec![leaf.clone(), leaf],
            centres: vec![[0.0; 64]; 2],
            half_norm2: vec![0.0; 2],
            idf: Vec::new(),
            max_words_per_frame: per_frame,
        };
        let mut rng = SplitMix64::new(seed);
        let mut words = 0usize;
        for (root, pool) in pools.iter().enumerate() {
            vocab.grow(root, pool, cfg.depth, cfg, &mut rng, &mut words);
        }
        vocab.half_norm2 = vocab.centres.iter().map(|c| 0.5 * norm2(c)).collect();
        VocabularyTraining {
            vocab,
            df: vec![0; words],
            frame_words: Vec::new(),
        }
    }

    /// The words of more training frames, counted into the document
    /// frequencies. Every frame the tree was trained on is added once, in
    /// the same order.
    pub fn add(&mut self, sets: &[&Features]) {
        for f in sets {
            let idx = strongest(f, self.vocab.max_words_per_frame);
            let fw = self.vocab.words_of(f, &idx);
            let mut last = None;
            for &w in &fw {
                if last != Some(w) {
                    self.df[w as usize] += 1;
                    last = Some(w);
                }
            }
            self.frame_words.push((fw, idx.len()));
        }
    }

    /// The vocabulary, each word weighted by `ln(N / nᵢ)` over the `N`
    /// frames added, and the bag of every frame added, in order.
    pub fn finish(mut self) -> (Vocabulary, Vec<Bag>) {
        let n = self.frame_words.len().max(1) as f32;
        self.vocab.idf = self
            .df
            .iter()
            .map(|&d| (n / d.max(1) as f32).ln())
            .collect();
        let bags = self
            .frame_words
            .iter()
            .map(|(fw, total)| self.vocab.weigh(fw, *total))
            .collect();
        (self.vocab, bags)
    }
}

/// Cosine similarity of two bags (0 when either is empty).
pub fn similarity(a: &Bag, b: &Bag) -> f64 {
    let (mut i, mut j, mut s) = (0, 0, 0f64);
    while i < a.words.len() && j < b.words.len() {
        let (wa, va) = a.words[i];
        let (wb, vb) = b.words[j];
        match wa.cmp(&wb) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                s += va as f64 * vb as f64;
                i += 1;
                j += 1;
            }
        }
    }
    s
}

/// One row of the similarity matrix: `bag` against every frame of the
/// inverted file. (A function per row: a wasm engine optimises a function
/// after a few calls, never a loop that is already running.)
fn score_row(bag: &Bag, postings: &[Vec<(u32, f32)>], row: &mut [f64]) {
    for &(w, va) in &bag.words {
        for &(j, vb) in &postings[w as usize] {
            if let Some(r) = row.get_mut(j as usize) {
                *r += va as f64 * vb as f64;
            }
        }
    }
}

/// The `k` best `(index, score)` of `scores` with a positive score, best
/// first (ties: lower index first).
fn top_k(scores: &[f64], k: usize) -> Vec<(usize, f64)> {
    let mut v: Vec<(usize, f64)> = scores
        .iter()
        .copied()
        .enumerate()
        .filter(|(_, s)| *s > 0.0)
        .collect();
    v.sort_by(|x, y| y.1.total_cmp(&x.1).then(x.0.cmp(&y.0)));
    v.truncate(k);
    v
}

/// One more than the largest word of any of `bags` (0 when they are empty).
pub fn word_count<'a>(bags: impl IntoIterator<Item = &'a Bag>) -> usize {
    bags.into_iter()
        .flat_map(|b| b.words.iter().map(|(w, _)| *w as usize + 1))
        .max()
        .unwrap_or(0)
}

/// The inverted file of `bags`: for each of `words` words (at least
/// [`word_count`] of them), the bags that hold it, as (position, weight).
pub fn inverted_file<'a>(
    bags: impl IntoIterator<Item = &'a Bag>,
    words: usize,
) -> Vec<Vec<(u32, f32)>> {
    let mut postings: Vec<Vec<(u32, f32)>> = vec![Vec::new(); words];
    for (j, bag) in bags.into_iter().enumerate() {
        for &(w, v) in &bag.words {
            postings[w as usize].push((j as u32, v));
        }
    }
    postings
}

/// Frame pairs `(index in bags_a, index in bags_b, similarity)` worth
/// verifying, best first: each frame of either robot nominates its
/// `per_frame` most similar frames of the other, and the union is cut to
/// `max_pairs`. Pairs with nothing in common are never proposed.
pub fn propose_pairs(
    bags_a: &[Bag],
    bags_b: &[Bag],
    per_frame: usize,
    max_pairs: usize,
) -> Vec<(usize, usize, f64)> {
    if bags_a.is_empty() || bags_b.is_empty() || per_frame == 0 || max_pairs == 0 {
        return Vec::new();
    }
    // Inverted file over B.
    let postings = inverted_file(bags_b, word_count(bags_a.iter().chain(bags_b)));
    // The full similarity matrix, row by row.
    let mut matrix = vec![0f64; bags_a.len() * bags_b.len()];
    for (i, bag) in bags_a.iter().enumerate() {
        score_row(
            bag,
            &postings,
            &mut matrix[i * bags_b.len()..(i + 1) * bags_b.len()],
        );
    }
    let mut pairs: Vec<(usize, usize, f64)> = Vec::new();
    for i in 0..bags_a.len() {
        let row = &matrix[i * bags_b.len()..(i + 1) * bags_b.len()];
        for (j, s) in top_k(row, per_frame) {
            pairs.push((i, j, s));
        }
    }
    let mut column = vec![0f64; bags_a.len()];
    for j in 0..bags_b.len() {
        for (i, c) in column.iter_mut().enumerate() {
            *c = matrix[i * bags_b.len() + j];
        }
        for (i, s) in top_k(&column, per_frame) {
            pairs.push((i, j, s));
        }
    }
    pairs.sort_by(|x, y| y.2.total_cmp(&x.2).then(x.0.cmp(&y.0)).then(x.1.cmp(&y.1)));
    pairs.dedup_by(|x, y| x.0 == y.0 && x.1 == y.1);
    pairs.truncate(max_pairs);
    pairs
}
