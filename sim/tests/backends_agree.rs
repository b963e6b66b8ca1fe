//! Backends against each other on seeded random thrust sequences.

use psa_sim::physics::{
    create_backend, crosscheck, random_thrust_sequence, tolerance, trajectory, BackendKind, BodyState, Deviation,
    PlaneConstraint, StartQuaternion, StepSettings, Stepper,
};
use psa_sim::psa::BodySettings;

#[test]
fn native_matches_ode_within_1e_9_on_100_random_sequences() {
    let model = BodySettings::default().model().unwrap();
    let report = crosscheck(&model, &StepSettings::default(), 100, 500, 7).unwrap();
    let native = report
        .comparisons
        .iter()
        .find(|c| c.backend == BackendKind::Native)
        .unwrap();
    assert!(native.deviation.position <= 1e-9, "{:?}", native.deviation);
    assert!(native.deviation.heading <= 1e-9, "{:?}", native.deviation);
    assert!(native.deviation.velocity <= 1e-9, "{:?}", native.deviation);
    assert!(native.passed);
    // The sequences really move the body: a do-nothing backend would fail.
    let commands = random_thrust_sequence(7, 0, 500, 4);
    let mut ode = create_backend(BackendKind::Ode, &model, &StepSettings::default()).unwrap();
    let end = *trajectory(ode.as_mut(), &BodyState::default(), &commands)
        .unwrap()
        .last()
        .unwrap();
    assert!(end.x.hypot(end.y) > 0.1 && end.omega.abs() > 0.1, "{end:?}");
}

#[cfg(feature = "rapier")]
#[test]
fn rapier_agrees_with_ode_within_its_stated_tolerance() {
    let model = BodySettings::default().model().unwrap();
    let report = crosscheck(&model, &StepSettings::default(), 100, 500, 11).unwrap();
    let rapier = report
        .comparisons
        .iter()
        .find(|c| c.backend == BackendKind::Rapier)
        .unwrap();
    assert_eq!(rapier.tolerance, tolerance(BackendKind::Rapier));
    assert!(rapier.passed, "{:?} exceeds {:?}", rapier.deviation, rapier.tolerance);
}

fn max_deviation(a: StepSettings, b: StepSettings, sequences: u64) -> (Deviation, bool) {
    let model = BodySettings::default().model().unwrap();
    let mut x = create_backend(BackendKind::Ode, &model, &a).unwrap();
    let mut y = create_backend(BackendKind::Ode, &model, &b).unwrap();
    let start = BodyState {
        omega: 0.5,
        vy: 0.1,
        ..BodyState::default()
    };
    let mut worst = Deviation::between(&start, &start);
    let mut identical = true;
    for i in 0..sequences {
        let commands = random_thrust_sequence(3, i, 500, 4);
        let tx = trajectory(x.as_mut(), &start, &commands).unwrap();
        let ty = trajectory(y.as_mut(), &start, &commands).unwrap();
        identical &= tx == ty;
        for (p, q) in tx.iter().zip(&ty) {
            worst = worst.max(Deviation::between(p, q));
        }
    }
    (worst, identical)
}

#[test]
fn plane2d_joint_and_no_joint_give_identical_trajectories() {
    // Why no joint is the default: with every force in the mid-plane the
    // body never leaves the plane, and the joint's constraint forces are
    // exactly zero, so the trajectories are bit-identical.
    let free = StepSettings::default();
    assert_eq!(free.plane_constraint, PlaneConstraint::None);
    let joint = StepSettings {
        plane_constraint: PlaneConstraint::Plane2dJoint,
        ..free
    };
    let (worst, identical) = max_deviation(free, joint, 50);
    assert!(identical, "trajectories differ by {worst:?}");
}

#[test]
fn quick_step_agrees_with_the_exact_stepper() {
    let exact = StepSettings::default();
    let quick = StepSettings {
        stepper: Stepper::Quick,
        ..exact
    };
    let (worst, _) = max_deviation(exact, quick, 10);
    assert!(worst.within(&tolerance(BackendKind::Native)), "{worst:?}");
}

/// The start states of `native` and `ode` from `heading`, as each backend
/// keeps them (quaternion included).
fn start_quaternions(settings: &StepSettings, heading: f64) -> ([f64; 2], [f64; 2]) {
    let model = BodySettings::default().model().unwrap();
    let start = BodyState {
        heading,
        omega: 0.5,
        ..BodyState::default()
    };
    let mut quaternions = [[0.0; 2]; 2];
    for (q, kind) in quaternions.iter_mut().zip([BackendKind::Native, BackendKind::Ode]) {
        let mut backend = create_backend(kind, &model, settings).unwrap();
        backend.reset(&start).unwrap();
        *q = backend.planar_state().quaternion;
    }
    (quaternions[0], quaternions[1])
}

#[test]
fn native_starts_from_the_quaternion_ode_sets_on_any_heading() {
    // 2000 headings spread over a turn by an irrational step, off the
    // round values the tasks use.
    let step = std::f64::consts::TAU / (2000.0 * std::f64::consts::SQRT_2);
    let headings: Vec<f64> = (0..2000).map(|k| -3.0 + step * f64::from(k) * 1.4).collect();
    for &h in &headings {
        let (native, ode) = start_quaternions(&StepSettings::default(), h);
        assert_eq!(native.map(f64::to_bits), ode.map(f64::to_bits), "heading {h}");
    }
    // The earlier, raw quaternion is (cos h/2, sin h/2) as computed, and
    // ODE's normalisation moves it for a good share of these headings.
    let raw = StepSettings {
        start_quaternion: StartQuaternion::Raw,
        ..StepSettings::default()
    };
    let mut moved = 0;
    for &h in &headings {
        let (native, ode) = start_quaternions(&raw, h);
        assert_eq!(native, [(0.5 * h).cos(), (0.5 * h).sin()]);
        moved += usize::from(native != ode);
    }
    assert!(
        moved > headings.len() / 20,
        "ODE moved only {moved} of {} start quaternions",
        headings.len()
    );
}
