//! Integrators: turn a camera ray into radiance.
//!
//! * [`photon`]: Jensen's photon-mapping estimator.

pub mod photon;

/// What a thread counted while it shaded: rays cast, and samples whose
/// radiance came out non-finite (a bug at some estimator; never written).
#[derive(Clone, Copy, Debug, Default)]
pub struct Tally {
    pub rays: u64,
    pub nonfinite: u64,
    /// Pixels given extra samples on the rim of a light's image.
    pub edge_pixels: usize,
    /// First non-finite sample seen: (pixel index, estimator name).
    pub first_nonfinite: Option<(u64, &'static str)>,
}

impl Tally {
    pub fn merge(mut self, other: Tally) -> Tally {
        self.rays += other.rays;
        self.nonfinite += other.nonfinite;
        self.edge_pixels += other.edge_pixels;
        self.first_nonfinite = match (self.first_nonfinite, other.first_nonfinite) {
            (Some(a), Some(b)) => Some(if a.0 <= b.0 { a } else { b }),
            (a, b) => a.or(b),
        };
        self
    }
}
