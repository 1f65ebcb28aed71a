//! The form-factor study measures what it claims: exact methods come out exact, sampled ones
//! improve as they are given more, and the hemicube aliases on patches about a pixel in size.

use penumbra::experiments::form_factors::{ALIASING_SIDES, StudyOptions, run_study};

#[test]
fn the_study_tells_the_methods_apart() {
    let study = run_study(&StudyOptions {
        rays: 16,
        samples: vec![16, 1024],
        resolutions: vec![16, 64, 256],
        streams: 8,
        cube_elements: 300,
    })
    .expect("the study runs");
    let row = |label: &str, setting: usize| {
        study
            .points
            .iter()
            .find(|r| r.config.label.starts_with(label) && r.config.setting == setting)
            .expect("measured")
    };
    // Cases 0-3 are unoccluded: Lambert's formula is exact there.
    for e in &row("analytic", 16).errors[..4] {
        assert!(*e < 1e-12, "{e}");
    }
    // Monte Carlo: 64 times the samples, about 8 times less error (at least 3 times).
    for case in 0..study.cases.len() {
        let (few, many) = (
            row("monte", 16).errors[case],
            row("monte", 1024).errors[case],
        );
        assert!(many < few / 3.0, "case {case}: {few} then {many}");
    }
    // The hemicube on unoccluded polygons: second order in the pixel size, so 16 times the
    // resolution gives far less than a sixteenth of the error.
    for case in 0..4 {
        let (coarse, fine) = (
            row("hemicube", 16).errors[case],
            row("hemicube", 256).errors[case],
        );
        assert!(
            fine < coarse / 16.0 && fine < 1e-4,
            "case {case}: {coarse} then {fine}"
        );
    }
    // Aliasing: a square under a pixel is seen whole or not at all; one of 16.5 pixels is right
    // to a few per cent wherever it sits.
    let aliasing: Vec<_> = study
        .aliasing
        .iter()
        .filter(|r| r.config.label.starts_with("hemicube"))
        .collect();
    assert_eq!(aliasing.len(), ALIASING_SIDES.len());
    let smallest = aliasing[0];
    assert!(
        smallest.min_ratio == 0.0 && smallest.max_ratio > 2.0,
        "{smallest:?}"
    );
    let largest = aliasing[aliasing.len() - 1];
    assert!(
        largest.min_ratio > 0.9 && largest.max_ratio < 1.1,
        "{largest:?}"
    );
    // Face factors of the 1 x 2 x 3 box: rows sum to 1 for Lambert to rounding.
    assert!(study.box_factors[0].worst_row_sum < 1e-6);
    // The unit cube's face means are near the continuous limit for every method: within 2 %
    // with Lambert (the coarse mesh's error), within 10 % even with 16 Monte Carlo samples.
    for r in &study.cube {
        let bound = if r.config.label.starts_with("analytic") {
            0.02
        } else {
            0.1
        };
        for e in r.errors {
            assert!(
                e.abs() < bound,
                "{} {}: {e}",
                r.config.label,
                r.config.setting
            );
        }
    }
}
