//! Maps over runs of equal values: a function evaluated once per run of consecutive equal inputs
//! rather than once per input. A flat background (one value across most of an image row) then
//! costs one evaluation, which is where the metrics' per-pixel transcendental functions (the
//! VDP's logarithms and adaptation gains, FLIP's colour conversion to CIELAB) spend their time on
//! rendered images.

/// `f` of every item of `values`, evaluated once per run of equal items: the same values as
/// mapping every item, for an `f` that maps equal items alike (runs compare with `==`, so 0 and
/// −0 share a run).
pub(crate) fn map_runs<T: PartialEq + Copy, U: Copy>(
    values: impl IntoIterator<Item = T>,
    f: impl Fn(T) -> U,
) -> impl Iterator<Item = U> {
    let mut last: Option<(T, U)> = None;
    values.into_iter().map(move |x| match last {
        Some((m, y)) if m == x => y,
        _ => {
            let y = f(x);
            last = Some((x, y));
            y
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_give_what_mapping_every_item_gives_with_one_call_per_run() {
        let values = [1.0f32, 1.0, 2.0, 2.0, 2.0, 1.0, -0.0, 0.0, 3.0];
        let calls = std::cell::Cell::new(0);
        let mapped: Vec<f32> = map_runs(values, |x| {
            calls.set(calls.get() + 1);
            x * 10.0 + 1.0
        })
        .collect();
        let every: Vec<f32> = values.iter().map(|x| x * 10.0 + 1.0).collect();
        assert_eq!(mapped, every);
        // Runs: [1, 1], [2, 2, 2], [1], [−0, 0], [3].
        assert_eq!(calls.get(), 5);
    }
}
