//! Iterate averaging (Polyak–Ruppert): the running mean of parameter vectors, shared by
//! meta-training (`meta_training.average_last`) and online adaptation
//! (`adaptation.average_last_pass`).

/// The sum and count of the parameter vectors added so far; a disabled mean ignores them.
pub(crate) struct IterateMean {
    sum: Vec<f64>,
    count: usize,
}

impl IterateMean {
    /// A mean of vectors of length `size`, or one that ignores every vector if not `enabled`.
    pub(crate) fn new(size: usize, enabled: bool) -> Self {
        Self {
            sum: if enabled { vec![0.0; size] } else { Vec::new() },
            count: 0,
        }
    }

    /// Adds one iterate (nothing when disabled).
    pub(crate) fn add(&mut self, parameters: &[f64]) {
        if self.sum.is_empty() {
            return;
        }
        self.count += 1;
        for (s, p) in self.sum.iter_mut().zip(parameters) {
            *s += p;
        }
    }

    /// The mean of the added iterates, or `last` when none was added.
    pub(crate) fn finish(self, last: Vec<f64>) -> Vec<f64> {
        if self.count == 0 {
            return last;
        }
        let scale = 1.0 / self.count as f64;
        self.sum.into_iter().map(|s| s * scale).collect()
    }
}
