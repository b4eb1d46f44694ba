//! Disjoint sets over point indices (union-find), for the connected parts
//! of neighbour graphs (regions of a segmentation, components of a cloud).

/// Disjoint sets over point indices (path halving, union by index so the
/// result does not depend on the order the unions arrive in).
pub(crate) struct Forest(Vec<u32>);

impl Forest {
    /// `n` singletons.
    pub(crate) fn new(n: usize) -> Self {
        Self((0..n as u32).collect())
    }

    /// The root of `i`'s set: the smallest index in it.
    pub(crate) fn root(&mut self, mut i: u32) -> u32 {
        while self.0[i as usize] != i {
            let up = self.0[self.0[i as usize] as usize];
            self.0[i as usize] = up;
            i = up;
        }
        i
    }

    /// Joins the sets of `a` and `b`; true when they were apart.
    pub(crate) fn join(&mut self, a: u32, b: u32) -> bool {
        let (ra, rb) = (self.root(a), self.root(b));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.0[hi as usize] = lo;
        }
        ra != rb
    }
}
