//! # The surface layer, kept only where surfaces are
//!
//! The SLAM map keeps, per cell, where inside it the surface lies (the
//! running mean of the hits that ended there, [`super::grid`]'s "surface
//! layer"). Stored densely beside the log-odds, that is 6 bytes for every
//! cell of the grid's window, six times the log-odds themselves, although
//! only cells a beam *ended* in ever hold one: the walls, a thin line
//! through a mostly free or unknown window. Measured on a crowded maze (16
//! robots × 900 s, `crate/examples/memory.rs`), the dense layer was 93 MB
//! of the robots' 125 MB of maps.
//!
//! So the layer is *sparse by blocks*, the layout of a paged or tiled
//! sparse array (as in OpenVDB's leaf nodes, Museth 2013, at one level):
//! the grid's window is cut into blocks of [`BLOCK`] × [`BLOCK`] cells; a
//! small dense index (4 bytes a block) says, for each, where in a pool its
//! cells lie, or that it has none. A block is allocated the first time a
//! hit ends in one of its cells and is never freed (a cell cleared to free
//! only resets its count, as before). Reading a cell is two index
//! computations and one indirection; a missing block reads as "no hit".
//!
//! The grid's origin and size are multiples of its growth step (64 cells),
//! so blocks keep their alignment when it grows: growing re-lays the index
//! only, the pool is not copied.

/// Cells on a side of a block (the grid's growth step is a multiple).
pub const BLOCK: usize = 4;
const CELLS: usize = BLOCK * BLOCK;
/// Where local cell `(x, y)` lies in its block ([`SurfaceBlocks::block_of`]).
#[inline]
pub const fn slot(x: usize, y: usize) -> usize {
    (y % BLOCK) * BLOCK + x % BLOCK
}
/// The index's mark of a block without cells.
const NONE: u32 = u32::MAX;

/// Where the surface lies inside one cell: the running mean of the hits
/// that ended in it, as an offset from the cell's centre in units of
/// 1/65536 of a cell, over the last [`super::grid::SURFACE_WINDOW`] hits,
/// and how many hits it has had in all.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct SurfaceCell {
    pub hits: u16,
    pub offset: [i16; 2],
}

/// The surface cells of a grid `width` × `height` cells (local indices),
/// allocated by blocks where hits are.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct SurfaceBlocks {
    /// Blocks a row of the index.
    cols: usize,
    /// Pool position of each block, row by row (`NONE`: no cells).
    #[serde(with = "super::keep_capacity")]
    index: Vec<u32>,
    #[serde(with = "super::keep_capacity")]
    pool: Vec<[SurfaceCell; CELLS]>,
}

impl SurfaceBlocks {
    /// Block `(bx, by)` of the index and the cell's place in it.
    #[inline]
    fn locate(&self, x: usize, y: usize) -> (usize, usize) {
        ((y / BLOCK) * self.cols + x / BLOCK, slot(x, y))
    }

    /// The surface of local cell `(x, y)`, if its block has cells.
    #[inline]
    pub fn get(&self, x: usize, y: usize) -> Option<&SurfaceCell> {
        let (b, c) = self.locate(x, y);
        match *self.index.get(b)? {
            NONE => None,
            p => Some(&self.pool[p as usize][c]),
        }
    }

    /// The block holding local cell `(x, y)`, if it has cells; the cell is
    /// its entry [`slot`]`(x, y)`. A walk along a row looks a block up
    /// once for its (up to) [`BLOCK`] cells.
    #[inline]
    pub fn block_of(&self, x: usize, y: usize) -> Option<&[SurfaceCell; CELLS]> {
        let (b, _) = self.locate(x, y);
        match *self.index.get(b)? {
            NONE => None,
            p => Some(&self.pool[p as usize]),
        }
    }

    /// The surface of local cell `(x, y)` to change, if its block has cells
    /// (nothing is allocated).
    #[inline]
    pub fn get_mut(&mut self, x: usize, y: usize) -> Option<&mut SurfaceCell> {
        let (b, c) = self.locate(x, y);
        match *self.index.get(b)? {
            NONE => None,
            p => Some(&mut self.pool[p as usize][c]),
        }
    }

    /// The surface of local cell `(x, y)`, its block allocated if need be.
    /// # Panics
    /// If the cell lies outside the window given to [`Self::regrid`].
    pub fn entry(&mut self, x: usize, y: usize) -> &mut SurfaceCell {
        let (b, c) = self.locate(x, y);
        if self.index[b] == NONE {
            if self.pool.len() == self.pool.capacity() {
                // Grow by a quarter, not double: the pool is most of the
                // layer, and its spare room is memory nobody uses.
                self.pool.reserve_exact(self.pool.len() / 4 + 64);
            }
            self.index[b] = self.pool.len() as u32;
            self.pool.push([SurfaceCell::default(); CELLS]);
        }
        &mut self.pool[self.index[b] as usize][c]
    }

    /// Re-lays the index for a window grown to `width` × `height` cells in
    /// which the old one's cell (0, 0) lies at `(dx, dy)` (all multiples of
    /// [`BLOCK`]; `old_height` is the old window's height). The pool stays.
    pub fn regrid(&mut self, width: usize, height: usize, dx: usize, dy: usize, old_height: usize) {
        debug_assert!([width, height, dx, dy].iter().all(|v| v % BLOCK == 0));
        let cols = width / BLOCK;
        let mut index = vec![NONE; cols * (height / BLOCK)];
        for row in 0..old_height / BLOCK {
            let src = &self.index[row * self.cols..(row + 1) * self.cols];
            let start = (row + dy / BLOCK) * cols + dx / BLOCK;
            index[start..start + self.cols].copy_from_slice(src);
        }
        self.index = index;
        self.cols = cols;
    }

    /// Bytes held (index and pool).
    pub fn memory_bytes(&self) -> usize {
        self.index.capacity() * std::mem::size_of::<u32>()
            + self.pool.capacity() * std::mem::size_of::<[SurfaceCell; CELLS]>()
    }

    /// Blocks allocated.
    pub fn blocks(&self) -> usize {
        self.pool.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_are_allocated_by_block_and_survive_regridding() {
        let mut s = SurfaceBlocks::default();
        s.regrid(8, 8, 0, 0, 0);
        assert_eq!(s.get(5, 6), None);
        s.entry(5, 6).hits = 3;
        // One block of 16 cells: its neighbours in the block read zero.
        assert_eq!(s.blocks(), 1);
        assert_eq!(s.get(4, 7).map(|c| c.hits), Some(0));
        assert_eq!(s.get(3, 6), None);
        // Grown by 4 cells to the left and 8 below: the cell moves with it.
        s.regrid(16, 16, 4, 8, 8);
        assert_eq!(s.get(9, 14).map(|c| c.hits), Some(3));
        assert_eq!(s.get(5, 6), None);
        assert_eq!(s.blocks(), 1);
        assert_eq!(s.memory_bytes(), 16 * 4 + 64 * 16 * 6);
    }
}
