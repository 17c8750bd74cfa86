//! Summary statistics over per-frame samples.

/// Median, mean, percentiles and range of a sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Summary {
    pub median: f64,
    pub mean: f64,
    pub p95: f64,
    pub p99: f64,
    pub min: f64,
    pub max: f64,
    pub count: usize,
}

impl Summary {
    /// Summarises `samples` (NaNs are ignored). The median of an even count is the mean of the
    /// two middle values; percentiles use the nearest rank.
    pub fn of(samples: &[f64]) -> Summary {
        let mut sorted: Vec<f64> = samples.iter().copied().filter(|v| !v.is_nan()).collect();
        if sorted.is_empty() {
            return Summary::default();
        }
        sorted.sort_by(f64::total_cmp);
        let n = sorted.len();
        let median = if n % 2 == 1 {
            sorted[n / 2]
        } else {
            (sorted[n / 2 - 1] + sorted[n / 2]) / 2.0
        };
        Summary {
            median,
            mean: sorted.iter().sum::<f64>() / n as f64,
            p95: zoo_host::judge::percentile(&sorted, 0.95),
            p99: zoo_host::judge::percentile(&sorted, 0.99),
            min: sorted[0],
            max: sorted[n - 1],
            count: n,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_data() {
        let data: Vec<f64> = (1..=100).map(f64::from).collect();
        let s = Summary::of(&data);
        assert_eq!(s.median, 50.5);
        assert_eq!(s.p95, 95.0);
        assert_eq!(s.p99, 99.0);
        assert_eq!((s.min, s.max, s.count), (1.0, 100.0, 100));
        let s = Summary::of(&[3.0, 1.0, 2.0]);
        assert_eq!((s.median, s.p95, s.min, s.max), (2.0, 3.0, 1.0, 3.0));
        let s = Summary::of(&[5.0, f64::NAN, 7.0]);
        assert_eq!((s.median, s.count), (6.0, 2));
        assert_eq!(Summary::of(&[]), Summary::default());
        // Order does not matter.
        let shuffled = [9.0, 2.0, 7.0, 4.0, 5.0, 6.0, 3.0, 8.0, 1.0, 10.0];
        assert_eq!(Summary::of(&shuffled).median, 5.5);
        assert_eq!(Summary::of(&shuffled).p95, 10.0);
    }
}
