//! Uniform random points over a set of triangles: a triangle drawn by its share of the total
//! area, then a point uniform inside it.

use crate::SplitMix64;

/// Draws triangles by area from their running totals.
#[derive(Clone, Debug, Default)]
pub struct AreaSampler {
    cumulative: Vec<f64>,
}

impl AreaSampler {
    /// A sampler over triangles of these areas, in order.
    pub fn new(areas: impl IntoIterator<Item = f64>) -> AreaSampler {
        let mut total = 0.0;
        let cumulative = areas
            .into_iter()
            .map(|a| {
                total += a;
                total
            })
            .collect();
        AreaSampler { cumulative }
    }

    /// The triangles' total area.
    pub fn total(&self) -> f64 {
        self.cumulative.last().copied().unwrap_or(0.0)
    }

    /// A triangle's index and the barycentric weights of a uniform point in it, from three
    /// draws of `rng`; `None` when there are no triangles.
    pub fn pick(&self, rng: &mut SplitMix64) -> Option<(usize, [f64; 3])> {
        let last = self.cumulative.len().checked_sub(1)?;
        let u = rng.next_f64() * self.total();
        let k = self.cumulative.partition_point(|&c| c < u).min(last);
        let (r1, r2) = (rng.next_f64().sqrt(), rng.next_f64());
        Some((k, [1.0 - r1, r1 * (1.0 - r2), r1 * r2]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Triangles are drawn in proportion to their areas, and the weights are barycentric.
    #[test]
    fn draws_follow_the_areas() {
        let sampler = AreaSampler::new([1.0, 3.0, 0.0]);
        assert_eq!(sampler.total(), 4.0);
        let mut rng = SplitMix64::new(5);
        let mut counts = [0usize; 3];
        for _ in 0..40_000 {
            let (k, w) = sampler.pick(&mut rng).expect("triangles");
            assert!(w.iter().all(|&x| (0.0..=1.0).contains(&x)));
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            counts[k] += 1;
        }
        assert_eq!(counts[2], 0);
        let share = counts[1] as f64 / 40_000.0;
        assert!((share - 0.75).abs() < 0.01, "{share}");
        assert!(AreaSampler::new([]).pick(&mut rng).is_none());
    }
}
