//! Efficiency statistics of the operations (connectivity move × optimization level) and the
//! decision whether to attempt one (Lindstrom & Turk §5.3, inequality 3).
//!
//! For each operation: the mean energy change ΔE of its attempts (zero for a rejected attempt),
//! its standard deviation σ, the mean completion time t (in energy evaluations, as the paper
//! counts time for reproducibility) and the frequency f — all under a weighting that attenuates
//! every past attempt by [`DECAY`] whenever any operation completes. The most efficient
//! operation O* has the lowest ΔE/t. An operation O is attempted when
//!
//! ΔE ≤ min{ ΔE*·t/t* + √2·erf⁻¹(f*/(f + f*))·σ, ΔE_total }
//!
//! (the paper writes `<`; with `≤` the best operation is still attempted once every mean is zero,
//! at convergence, instead of the optimizer stalling). An operation never attempted is always tried.

use statrs::function::erf::erf_inv;

/// Attenuation of the statistics per completed operation.
pub const DECAY: f64 = 0.99;

/// A connectivity move.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Move {
    /// Optimize geometry only (levels 1–3).
    NoOp,
    /// Edge swap (levels 0–3).
    Swap,
    /// Vertex teleport: edge split then an edge collapse elsewhere (levels 0–3 of the split).
    Teleport,
}

impl Move {
    /// Name for logs and CSV.
    pub fn name(self) -> &'static str {
        match self {
            Move::NoOp => "no-op",
            Move::Swap => "swap",
            Move::Teleport => "teleport",
        }
    }
    /// The optimization levels the move has (Table 1).
    pub fn levels(self) -> std::ops::RangeInclusive<u8> {
        match self {
            Move::NoOp => 1..=3,
            Move::Swap | Move::Teleport => 0..=3,
        }
    }
    /// Every move, in the order they are tried on an edge.
    pub const ALL: [Move; 3] = [Move::NoOp, Move::Swap, Move::Teleport];
}

/// Attenuated sums of one operation's attempts.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Sums {
    weight: f64,
    delta: f64,
    delta_sq: f64,
    time: f64,
}

impl Sums {
    fn mean(&self) -> f64 {
        self.delta / self.weight
    }
    fn sigma(&self) -> f64 {
        let m = self.mean();
        (self.delta_sq / self.weight - m * m).max(0.0).sqrt()
    }
    fn time(&self) -> f64 {
        (self.time / self.weight).max(1.0)
    }
    fn efficiency(&self) -> f64 {
        self.mean() / self.time()
    }
}

/// Statistics of every operation.
#[derive(Debug, Clone, Default)]
pub struct Stats {
    ops: Vec<((Move, u8), Sums)>,
}

impl Stats {
    /// No history.
    pub fn new() -> Stats {
        let ops = Move::ALL
            .iter()
            .flat_map(|&m| m.levels().map(move |l| ((m, l), Sums::default())))
            .collect();
        Stats { ops }
    }

    fn get(&self, op: (Move, u8)) -> Sums {
        self.ops
            .iter()
            .find(|(k, _)| *k == op)
            .map(|(_, s)| *s)
            .unwrap_or_default()
    }

    /// Record an attempt of `op` that changed the energy by `delta` in `evals` evaluations.
    pub fn record(&mut self, op: (Move, u8), delta: f64, evals: usize) {
        for (k, s) in &mut self.ops {
            s.weight *= DECAY;
            s.delta *= DECAY;
            s.delta_sq *= DECAY;
            s.time *= DECAY;
            if *k == op {
                s.weight += 1.0;
                s.delta += delta;
                s.delta_sq += delta * delta;
                s.time += evals as f64;
            }
        }
    }

    /// The most efficient operation with a history (lowest mean ΔE per evaluation).
    pub fn best(&self) -> Option<(Move, u8)> {
        self.ops
            .iter()
            .filter(|(_, s)| s.weight > 0.0)
            .min_by(|a, b| a.1.efficiency().total_cmp(&b.1.efficiency()))
            .map(|(k, _)| *k)
    }

    /// Inequality 3: whether to attempt `op` given the energy change `total` already made on the
    /// current edge.
    pub fn should_attempt(&self, op: (Move, u8), total: f64) -> bool {
        let s = self.get(op);
        let Some(best) = self.best() else {
            return true;
        };
        if s.weight <= 0.0 {
            return true;
        }
        let b = self.get(best);
        // f*/(f + f*) < 1 for f > 0; erf⁻¹ of ½ (op = O*) is 0.477.
        let z = erf_inv(b.weight / (s.weight + b.weight));
        let bound = b.mean() * s.time() / b.time() + std::f64::consts::SQRT_2 * z * s.sigma();
        s.mean() <= bound.min(total)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn untried_operations_are_attempted_and_the_best_is_found() {
        let mut st = Stats::new();
        assert!(st.should_attempt((Move::Swap, 2), 0.0));
        for _ in 0..20 {
            st.record((Move::NoOp, 1), -100.0, 10); // −10 per evaluation
            st.record((Move::Swap, 0), -5.0, 1); // −5 per evaluation
        }
        assert_eq!(st.best(), Some((Move::NoOp, 1)));
        // Never tried: still attempted.
        assert!(st.should_attempt((Move::Teleport, 3), 0.0));
    }

    #[test]
    fn a_clearly_worse_operation_is_skipped_and_a_rare_one_gets_a_chance() {
        let mut st = Stats::new();
        for k in 0..200 {
            // O*: mean −100 per 10 evaluations, some spread.
            st.record((Move::NoOp, 1), -100.0 + (k % 3) as f64, 10);
        }
        // A costly operation with no gain and no spread: skipped.
        for _ in 0..50 {
            st.record((Move::NoOp, 3), 0.0, 100);
        }
        assert!(!st.should_attempt((Move::NoOp, 3), 0.0));
        // A rarely tried one whose spread makes it plausibly better: attempted (erf⁻¹ of a
        // frequency ratio near 1 is large).
        st.record((Move::Swap, 0), 0.0, 1);
        st.record((Move::Swap, 0), -400.0, 1);
        assert!(st.should_attempt((Move::Swap, 0), 0.0));
        // ... but not when the current edge already made more progress than it promises.
        assert!(!st.should_attempt((Move::Swap, 0), -1e9));
    }

    #[test]
    fn at_convergence_the_best_operation_is_still_attempted() {
        let mut st = Stats::new();
        for _ in 0..10 {
            st.record((Move::NoOp, 1), 0.0, 5);
        }
        assert!(st.should_attempt((Move::NoOp, 1), 0.0));
    }
}
