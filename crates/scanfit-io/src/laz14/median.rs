//! LASzip's running predictor of coordinate differences: five sorted
//! values of which the middle one is the prediction. A new value replaces
//! an end of the window, alternately biased up and down (the `high` flag),
//! which is what the format specifies: it is not the median of the last
//! five values, and it must be reproduced exactly.

#[derive(Clone, Copy, Debug)]
pub(super) struct Median5 {
    v: [i32; 5],
    high: bool,
}

impl Median5 {
    pub(super) fn new() -> Self {
        Self {
            v: [0; 5],
            high: true,
        }
    }

    /// The prediction: the middle value.
    #[inline]
    pub(super) fn get(&self) -> i32 {
        self.v[2]
    }

    /// Inserts `x`, dropping the top value (when biased high) or the bottom
    /// value, and flips the bias when `x` lands on the other side.
    #[inline]
    pub(super) fn add(&mut self, x: i32) {
        let v = &mut self.v;
        if self.high {
            if x < v[2] {
                // drop v[4]: shift v[2..4] up, place x among v[0..3]
                v[4] = v[3];
                v[3] = v[2];
                if x < v[0] {
                    v[2] = v[1];
                    v[1] = v[0];
                    v[0] = x;
                } else if x < v[1] {
                    v[2] = v[1];
                    v[1] = x;
                } else {
                    v[2] = x;
                }
            } else {
                if x < v[3] {
                    v[4] = v[3];
                    v[3] = x;
                } else {
                    v[4] = x;
                }
                self.high = false;
            }
        } else if v[2] < x {
            // drop v[0]: shift v[1..3] down, place x among v[2..5]
            v[0] = v[1];
            v[1] = v[2];
            if v[4] < x {
                v[2] = v[3];
                v[3] = v[4];
                v[4] = x;
            } else if v[3] < x {
                v[2] = v[3];
                v[3] = x;
            } else {
                v[2] = x;
            }
        } else {
            if v[1] < x {
                v[0] = v[1];
                v[1] = x;
            } else {
                v[0] = x;
            }
            self.high = true;
        }
    }
}
