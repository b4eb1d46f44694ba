//! Disjoint sets over point indices (union-find), for the connected parts
//! of neighbour graphs (regions of a segmentation, components of a cloud).

use rayon::prelude::*;

/// Disjoint sets over point indices (path halving, union by index so the
/// result does not depend on the order the unions arrive in).
pub(crate) struct Forest(Vec<u32>);

impl Forest {
    /// `n` singletons.
    pub(crate) fn new(n: usize) -> Self {
        Self((0..n as u32).collect())
    }

    /// The root of `i`'s set: the smallest index in it.
    pub(crate) fn root(&mut self, i: u32) -> u32 {
        root_in(&mut self.0, 0, i)
    }

    /// Joins the sets of `a` and `b`; true when they were apart.
    pub(crate) fn join(&mut self, a: u32, b: u32) -> bool {
        join_in(&mut self.0, 0, a, b)
    }
}

/// [`Forest::root`] on the parents of the indices `off..off + parents.len()`
/// (a set that never leaves that range).
fn root_in(parents: &mut [u32], off: u32, mut i: u32) -> u32 {
    while parents[(i - off) as usize] != i {
        let up = parents[(parents[(i - off) as usize] - off) as usize];
        parents[(i - off) as usize] = up;
        i = up;
    }
    i
}

/// [`Forest::join`] on such a range.
fn join_in(parents: &mut [u32], off: u32, a: u32, b: u32) -> bool {
    let (ra, rb) = (root_in(parents, off, a), root_in(parents, off, b));
    if ra != rb {
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        parents[(hi - off) as usize] = lo;
    }
    ra != rb
}

/// The number of connected parts of the graph over `0..n` whose row `i`
/// (`k` entries of `rows`) lists the neighbours of `i`.
///
/// The two halves of the index range are joined on both threads, each over
/// its own edges, then the edges between the halves: the parts are those
/// of one pass over all edges (a count does not depend on the order of the
/// unions). Rows in a spatial order (a KD-tree's) have few edges between
/// the halves.
pub(crate) fn count_components(rows: &[u32], k: usize, n: usize) -> usize {
    let mut forest = Forest::new(n);
    if k == 0 {
        return n;
    }
    let m = n / 2;
    let (left, right) = forest.0.split_at_mut(m);
    let local = |parents: &mut [u32], off: usize, rows: &[u32]| -> usize {
        let end = off + parents.len();
        let mut joined = 0;
        for (r, row) in rows.chunks_exact(k).enumerate() {
            for &j in row {
                if (off..end).contains(&(j as usize)) {
                    joined += usize::from(join_in(parents, off as u32, (off + r) as u32, j));
                }
            }
        }
        joined
    };
    let (rows_l, rows_r) = rows.split_at(m * k);
    let (a, b) = rayon::join(|| local(left, 0, rows_l), || local(right, m, rows_r));
    let mut count = n - a - b;
    // the edges between the halves, on the whole forest
    let cross: Vec<(u32, u32)> = rows
        .par_chunks_exact(k)
        .enumerate()
        .flat_map_iter(|(i, row)| {
            row.iter()
                .filter(move |&&j| (i < m) != ((j as usize) < m))
                .map(move |&j| (i as u32, j))
        })
        .collect();
    for (i, j) in cross {
        count -= usize::from(forest.join(i, j));
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One pass over all edges in row order (the definition).
    fn serial(rows: &[u32], k: usize, n: usize) -> usize {
        let mut f = Forest::new(n);
        let mut count = n;
        for (i, row) in rows.chunks_exact(k).enumerate() {
            for &j in row {
                count -= usize::from(f.join(i as u32, j));
            }
        }
        count
    }

    #[test]
    fn halves_count_the_parts_of_one_pass() {
        // rings of 3 in a random permutation plus some long edges
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |m: u64| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) % m
        };
        for n in [1usize, 2, 3, 7, 100, 1001] {
            for k in [1usize, 2, 3] {
                for long in [0u64, 5, 50] {
                    let rows: Vec<u32> = (0..n * k)
                        .map(|e| {
                            let i = e / k;
                            if next(100) < long {
                                next(n as u64) as u32
                            } else {
                                (i / 3 * 3 + (i + 1 + e % k) % 3).min(n - 1) as u32
                            }
                        })
                        .collect();
                    assert_eq!(
                        count_components(&rows, k, n),
                        serial(&rows, k, n),
                        "n {n} k {k}"
                    );
                }
            }
        }
        // a known count: pairs (2i, 2i+1) of 10 points are 5 parts
        let rows: Vec<u32> = (0..10u32).map(|i| i ^ 1).collect();
        assert_eq!(count_components(&rows, 1, 10), 5);
    }
}
