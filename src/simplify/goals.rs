//! The checks of simplification goals, once for every caller: `lodeval simplify`'s flags, an
//! `eval` config's `generate`, the library's [`super::chain`] and Menzel & Guthe's own entry
//! point. A message names the goal and what is wrong with it, never a flag or a key, so that
//! each caller puts in front what the user wrote (`--error: …`, `asset 'a': generate …`).
//!
//! A goal is refused (a usage error, exit 2) when its value makes no LOD (a ratio or an error
//! outside (0, 1], Menzel & Guthe's error at 1 or above, a distance not above 0, a triangle
//! count outside the mesh's, fewer than 4 vertices), when the method cannot reach it (a distance
//! is Menzel & Guthe's, a vertex count is Qu & Meyer's remesh and theirs only), or when a chain
//! does not get coarser from one LOD to the next.

use super::{Goal, Method};

/// `Err` with the reason when `goals` cannot make a chain of LODs with `method`; `triangles`
/// is the mesh's triangle count where it is known (else triangle goals are only checked to be
/// at least 1).
pub fn check(method: Method, goals: &[Goal], triangles: Option<usize>) -> Result<(), String> {
    if goals.is_empty() {
        return Err(
            "there is no goal: give a ratio, a triangle count, an error, a distance \
                    (menzel-guthe) or a vertex count (qu-meyer)"
                .into(),
        );
    }
    for &g in goals {
        check_value(method, g, triangles)?;
    }
    check_method(method, goals)?;
    check_order(goals)
}

/// One goal's value.
fn check_value(method: Method, goal: Goal, triangles: Option<usize>) -> Result<(), String> {
    match goal {
        Goal::Distance(d) if !(d.is_finite() && d > 0.0) => Err(format!(
            "distance {d}: give a viewing distance in metres above 0"
        )),
        Goal::Ratio(r) if !(r.is_finite() && r > 0.0 && r <= 1.0) => Err(format!(
            "ratio {r} is outside (0, 1]: a ratio is a fraction of the original's triangles"
        )),
        Goal::Error(e)
            if method == Method::MenzelGuthe && !(e.is_finite() && e > 0.0 && e < 1.0) =>
        {
            Err(format!(
                "error {e} is outside (0, 1): an error is a fraction of the bounding-box diagonal"
            ))
        }
        Goal::Error(e) if !(e.is_finite() && e > 0.0 && e <= 1.0) => Err(format!(
            "error {e} is outside (0, 1]: an error is a fraction of the bounding-box diagonal"
        )),
        Goal::Triangles(t) => match triangles {
            Some(n) if t == 0 || t > n => Err(format!(
                "a goal of {t} triangles is outside 1..={n} (the mesh has {n}): give a smaller \
                 count, or a ratio"
            )),
            None if t == 0 => Err("a goal of 0 triangles: give at least 1".into()),
            _ => Ok(()),
        },
        Goal::Vertices(v) if v < crate::limits::REMESH_VERTICES.min as usize => {
            Err(format!("{v} vertices: a remesh needs at least 4"))
        }
        Goal::Vertices(v) => crate::limits::REMESH_VERTICES
            .check("vertices", v as u64)
            .map(|_| ()),
        _ => Ok(()),
    }
}

/// The goals the method can reach.
fn check_method(method: Method, goals: &[Goal]) -> Result<(), String> {
    let name = method.name();
    if method == Method::QuMeyer {
        return match goals.iter().find(|g| !matches!(g, Goal::Vertices(_))) {
            Some(g) => Err(format!("{name} remeshes to vertex counts only, not {g}")),
            None => Ok(()),
        };
    }
    if let Some(g) = goals.iter().find(|g| matches!(g, Goal::Vertices(_))) {
        return Err(format!(
            "{name} takes no vertex counts ({g}); those are for qu-meyer"
        ));
    }
    if method != Method::MenzelGuthe
        && let Some(d) = goals.iter().find(|g| matches!(g, Goal::Distance(_)))
    {
        return Err(format!(
            "{name} takes ratio, triangle or error goals, not a {d}; distances are for \
             menzel-guthe"
        ));
    }
    Ok(())
}

/// Each LOD of a chain is simpler than the one before: goals of one kind get coarser.
fn check_order(goals: &[Goal]) -> Result<(), String> {
    for pair in goals.windows(2) {
        let (coarser, kinds, verb) = match (pair[0], pair[1]) {
            (Goal::Ratio(a), Goal::Ratio(b)) => (b < a, "ratios", "decrease"),
            (Goal::Triangles(a), Goal::Triangles(b)) => (b < a, "triangle counts", "decrease"),
            (Goal::Error(a), Goal::Error(b)) => (b > a, "errors", "increase"),
            (Goal::Distance(a), Goal::Distance(b)) => (b > a, "distances", "increase"),
            (Goal::Vertices(a), Goal::Vertices(b)) => (b < a, "vertex counts", "decrease"),
            _ => continue,
        };
        let (a, b) = (pair[0], pair[1]);
        if !coarser {
            return Err(format!(
                "the goals do not get coarser: {kinds} must {verb} from one LOD to the next \
                 ({a} then {b}), each simplified from the one before; list them from the finest \
                 LOD to the coarsest (e.g. ratios 0.5, 0.25)"
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_refusal_names_the_goal_and_the_reason() {
        let cases: [(Method, Vec<Goal>, &str); 10] = [
            (Method::Qem, vec![], "no goal"),
            (
                Method::Qem,
                vec![Goal::Ratio(1.5)],
                "ratio 1.5 is outside (0, 1]",
            ),
            (
                Method::Qem,
                vec![Goal::Error(0.0)],
                "error 0 is outside (0, 1]",
            ),
            (
                Method::MenzelGuthe,
                vec![Goal::Error(1.0)],
                "outside (0, 1)",
            ),
            (
                Method::MenzelGuthe,
                vec![Goal::Distance(f64::NAN)],
                "above 0",
            ),
            (
                Method::Meshopt,
                vec![Goal::Distance(5.0)],
                "distances are for menzel-guthe",
            ),
            (
                Method::QuMeyer,
                vec![Goal::Ratio(0.5)],
                "vertex counts only",
            ),
            (
                Method::Qem,
                vec![Goal::Vertices(100)],
                "those are for qu-meyer",
            ),
            (Method::QuMeyer, vec![Goal::Vertices(3)], "at least 4"),
            (
                Method::MenzelGuthe,
                vec![Goal::Distance(10.0), Goal::Distance(5.0)],
                "distances must increase",
            ),
        ];
        for (method, goals, word) in cases {
            let e = check(method, &goals, Some(100)).unwrap_err();
            assert!(e.contains(word), "{goals:?}: {e}");
            assert!(!e.contains("--"), "no flag in the library's words: {e}");
        }
        assert!(check(Method::Qem, &[Goal::Triangles(101)], Some(100)).is_err());
        assert!(check(Method::Qem, &[Goal::Triangles(101)], None).is_ok());
        let fine = [Goal::Ratio(0.5), Goal::Ratio(0.25), Goal::Error(0.01)];
        assert_eq!(check(Method::Meshopt, &fine, Some(100)), Ok(()));
    }
}
