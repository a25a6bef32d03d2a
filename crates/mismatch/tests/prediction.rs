//! The prediction's shortcuts give its numbers: a wrench trace reused across effects with its
//! delay and motor lag (the searches and fits do so) gives the bits of a fresh prediction, and
//! one made for another timing is not used for it.

use mismatch::locate::forward::WrenchTrace;
use mismatch::{Problem, Recording, Settings};
use physics::{
    Delay, Effects, InertiaScale, LinearDrag, MotorLag, QuadraticDrag, ThrustScale, Wind, simulate,
};

mod common;

fn problem() -> Problem {
    let effects = Effects {
        linear_drag: Some(LinearDrag { d: [0.3, 0.3, 0.1] }),
        ..Effects::default()
    };
    let model = common::model_for_scenario();
    let log = simulate(&model, &common::scenario(effects, 5), "trace.csv").unwrap();
    let comparison = Settings::default().checked().unwrap().comparison;
    let recording = Recording::new(&log, &model, 40).unwrap();
    Problem::new(
        recording,
        model,
        comparison.test_function,
        comparison.heldout_fraction,
    )
    .unwrap()
}

fn bits(rows: &[[f64; 6]]) -> Vec<u64> {
    rows.iter().flatten().map(|v| v.to_bits()).collect()
}

#[test]
fn a_reused_wrench_trace_gives_a_fresh_predictions_bits() {
    let problem = problem();
    for timing in [
        Effects::default(),
        Effects {
            delay: Some(Delay { delay_s: 0.03 }),
            motor_lag: Some(MotorLag { tau_s: 0.05 }),
            ..Effects::default()
        },
    ] {
        let trace = WrenchTrace::new(&problem.recording, &problem.model, &timing);
        for others in [
            Effects::default(),
            Effects {
                quadratic_drag: Some(QuadraticDrag { c: 0.05 }),
                wind: Some(Wind {
                    w_air: [2.0, -1.0, 0.0],
                }),
                ..Effects::default()
            },
            Effects {
                thrust_scale: Some(ThrustScale { k: 0.9 }),
                inertia_scale: Some(InertiaScale { k: [1.2, 0.9, 1.1] }),
                ..Effects::default()
            },
        ] {
            let effects = Effects {
                delay: timing.delay,
                motor_lag: timing.motor_lag,
                ..others
            };
            assert!(trace.serves(&effects));
            assert_eq!(
                bits(&problem.predict_with(&effects, &trace)),
                bits(&problem.predict(&effects))
            );
        }
    }
    let still = WrenchTrace::new(&problem.recording, &problem.model, &Effects::default());
    let late = Effects {
        delay: Some(Delay { delay_s: 0.03 }),
        ..Effects::default()
    };
    assert!(!still.serves(&late));
    let refused = std::panic::catch_unwind(|| problem.predict_with(&late, &still));
    assert!(refused.is_err(), "a trace of another timing is not used");
}
