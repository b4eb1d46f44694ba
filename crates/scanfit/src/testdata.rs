//! Deterministic synthetic data for tests, benchmarks and examples: seeded
//! generators ([`Lcg`] for uniform numbers, [`SplitMix64`] with normal
//! deviates and random directions), scattered samples ([`scattered`]) and the
//! classic test function ([`franke`]), shared instead of a copy per test file. The same seed gives the same
//! numbers on every platform and in every release.

use crate::{Point3, Vector3};

/// A 64-bit linear congruential generator (Knuth's MMIX constants) with
/// 53-bit uniform doubles: tiny, fast and reproducible; not for anything that
/// needs statistical quality.
#[derive(Debug, Clone)]
pub struct Lcg(u64);

impl Lcg {
    /// A generator started from `seed`.
    ///
    /// ```
    /// use scanfit::testdata::Lcg;
    /// let (mut a, mut b) = (Lcg::new(42), Lcg::new(42));
    /// let x = a.next_f64();
    /// assert!((0.0..1.0).contains(&x));
    /// assert_eq!(x, b.next_f64());
    /// ```
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next uniform number in `[0, 1)`.
    pub fn next_f64(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Franke's test function on `[0, 1]^2` (R. Franke, *A critical comparison
/// of some methods for interpolation of scattered data*, NPS-53-79-003,
/// 1979): two Gaussian peaks, a ridge and a dip, values in about
/// `[-0.2, 1.2]`.
///
/// ```
/// let f = scanfit::testdata::franke(0.2, 0.2);
/// assert!(f > 0.7 && f < 1.3);
/// ```
pub fn franke(x: f64, y: f64) -> f64 {
    let (x9, y9) = (9.0 * x, 9.0 * y);
    0.75 * (-((x9 - 2.0).powi(2) + (y9 - 2.0).powi(2)) / 4.0).exp()
        + 0.75 * (-(x9 + 1.0).powi(2) / 49.0 - (y9 + 1.0) / 10.0).exp()
        + 0.5 * (-((x9 - 7.0).powi(2) + (y9 - 3.0).powi(2)) / 4.0).exp()
        - 0.2 * (-(x9 - 4.0).powi(2) - (y9 - 7.0).powi(2)).exp()
}

/// `n` points `(x, y, f(x, y))` with `(x, y)` uniform in the rectangle
/// `[x0, x0 + width) x [y0, y0 + height)`, drawn from [`Lcg::new(seed)`]
/// (x then y per point).
///
/// ```
/// use scanfit::testdata::{franke, scattered};
/// let p = scattered(1000, 7, [0.0, 0.0, 1.0, 1.0], |x, y| franke(x, y));
/// assert_eq!(p.len(), 1000);
/// assert!(p.iter().all(|q| (0.0..1.0).contains(&q.x) && (0.0..1.0).contains(&q.y)));
/// ```
pub fn scattered(
    n: usize,
    seed: u64,
    [x0, y0, width, height]: [f64; 4],
    f: impl Fn(f64, f64) -> f64,
) -> Vec<Point3> {
    let mut r = Lcg::new(seed);
    (0..n)
        .map(|_| {
            let (x, y) = (x0 + width * r.next_f64(), y0 + height * r.next_f64());
            Point3::new(x, y, f(x, y))
        })
        .collect()
}

/// The SplitMix64 generator (Steele, Lea & Flood 2014), with uniform and
/// normal deviates and uniform directions: the geometry tests' generator.
#[derive(Debug, Clone)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator started from (a scrambled) `seed`.
    ///
    /// ```
    /// use scanfit::testdata::SplitMix64;
    /// let mut r = SplitMix64::new(1);
    /// let v = r.unit_vector();
    /// assert!((v.norm() - 1.0).abs() < 1e-15);
    /// assert!((0.0..1.0).contains(&r.uniform()));
    /// ```
    pub fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Standard normal (Box-Muller).
    pub fn normal(&mut self) -> f64 {
        let u = 1.0 - self.uniform();
        let v = self.uniform();
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }

    /// Uniform on the unit sphere.
    pub fn unit_vector(&mut self) -> Vector3 {
        loop {
            let v = Vector3::new(self.normal(), self.normal(), self.normal());
            let n = v.norm();
            if n > 1e-9 {
                return v / n;
            }
        }
    }
}
