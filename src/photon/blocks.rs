//! The photons of a pass as the blocks they were traced in.
//!
//! The pass traces fixed-size blocks of emitted photons on all threads, and
//! the map build sorts them into Morton order anyway, so nothing needs them
//! joined: joining copied the default pass's 190 MB once more and faulted in
//! as much fresh memory. The blocks keep their order, so "photon i" (the
//! i-th photon of the blocks read in order) means what it meant in one
//! vector, and everything keyed by it stays thread-count independent.

use super::Photon;

/// Photons per entry of [`PhotonBlocks::locate`]'s table: fewer than a
/// block of the pass holds (4096 emitted, ~1 to ~5 stored each).
const STRIDE_BITS: u32 = 10;

#[derive(Clone, Debug, Default)]
pub struct PhotonBlocks {
    blocks: Vec<Vec<Photon>>,
    /// Index of each block's first photon, and the total at the end.
    starts: Vec<usize>,
    /// The block holding photon `j << STRIDE_BITS`, for each `j`.
    first_block: Vec<u32>,
}

impl PhotonBlocks {
    pub fn new(blocks: Vec<Vec<Photon>>) -> Self {
        let mut starts = Vec::with_capacity(blocks.len() + 1);
        let mut total = 0;
        for b in &blocks {
            starts.push(total);
            total += b.len();
        }
        starts.push(total);
        let first_block = (0..total.div_ceil(1 << STRIDE_BITS))
            .map(|j| (starts[1..].partition_point(|&s| s <= j << STRIDE_BITS)) as u32)
            .collect();
        PhotonBlocks { blocks, starts, first_block }
    }

    pub fn len(&self) -> usize {
        self.starts.last().copied().unwrap_or(0)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn blocks(&self) -> &[Vec<Photon>] {
        &self.blocks
    }

    /// Index of the first photon of block `b`.
    pub fn start(&self, b: usize) -> usize {
        self.starts[b]
    }

    pub fn iter(&self) -> impl Iterator<Item = &Photon> {
        self.blocks.iter().flatten()
    }

    /// Photon `i` (in block order); `i < len()`.
    #[inline]
    pub fn get(&self, i: usize) -> &Photon {
        let (b, j) = self.locate(i);
        &self.blocks[b][j]
    }

    /// (block, index in block) of photon `i`: the table names the block
    /// holding the stride's first photon; blocks longer than the stride are
    /// then at most one step away, taken without a branch (the map build
    /// looks up photons in random order, and a mispredicted branch there
    /// would cancel the memory reads in flight). Shorter or empty blocks
    /// take the loop.
    #[inline]
    fn locate(&self, i: usize) -> (usize, usize) {
        let mut b = self.first_block[i >> STRIDE_BITS] as usize;
        b += (self.starts[b + 1] <= i) as usize;
        while self.starts[b + 1] <= i {
            b += 1;
        }
        (b, i - self.starts[b])
    }

    /// One mutable slice of `out` per block, of the block's length, in order
    /// (`out` must be `len()` long): for filling per-photon data in parallel.
    pub fn split_like<'a, T>(&self, mut out: &'a mut [T]) -> Vec<&'a mut [T]> {
        assert_eq!(out.len(), self.len());
        let mut parts = Vec::with_capacity(self.blocks.len());
        for b in &self.blocks {
            let (head, tail) = out.split_at_mut(b.len());
            parts.push(head);
            out = tail;
        }
        parts
    }
}

impl From<Vec<Photon>> for PhotonBlocks {
    fn from(photons: Vec<Photon>) -> Self {
        PhotonBlocks::new(vec![photons])
    }
}

/// The same photons in the same order, however they are split into blocks.
impl PartialEq for PhotonBlocks {
    fn eq(&self, other: &Self) -> bool {
        self.len() == other.len() && self.iter().eq(other.iter())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn photon(i: usize) -> Photon {
        Photon { pos: [i as f32, 0.0, 0.0], ..Photon::default() }
    }

    #[test]
    fn photons_are_found_in_block_order_across_uneven_and_empty_blocks() {
        // Blocks shorter and longer than the table's stride, and empty ones
        // at the start, middle and end.
        let sizes = [0, 3, 5000, 0, 0, 1, 9000, 4096, 4095, 0, 12_289, 0];
        let mut next = 0;
        let blocks: Vec<Vec<Photon>> = sizes
            .iter()
            .map(|&n| {
                let b = (next..next + n).map(photon).collect();
                next += n;
                b
            })
            .collect();
        let photons = PhotonBlocks::new(blocks);
        assert_eq!(photons.len(), next);
        for i in 0..next {
            assert_eq!(photons.get(i).pos[0], i as f32, "photon {i}");
        }
        let flat: Vec<Photon> = photons.iter().copied().collect();
        assert!(flat.iter().enumerate().all(|(i, p)| p.pos[0] == i as f32));
        assert_eq!(photons, PhotonBlocks::from(flat));
        let mut keys = vec![0; next];
        for (b, part) in photons.split_like(&mut keys).into_iter().enumerate() {
            part.iter_mut().enumerate().for_each(|(j, k)| *k = photons.start(b) + j);
        }
        assert!(keys.iter().enumerate().all(|(i, &k)| k == i));
        assert!(PhotonBlocks::new(vec![vec![], vec![]]).is_empty());
        assert!(PhotonBlocks::default().is_empty());
    }
}
