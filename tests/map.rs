//! Maps over two parameters (docs/model.md section 6): rows are sweeps, curves are refined 1-D thresholds.

use vrw::family::Parameter;
use vrw::gait::GaitOptions;
use vrw::params::Config;
use vrw::reference::default_initial;
use vrw::study::map::{Along, DEFAULT_CURVE_COLUMNS};
use vrw::study::{find_thresholds, map_curves, map_gaits, sweep, MapSpec, SweepSpec};

/// Tolerance of every threshold in its parameter (the 1-D refinement's tolerance).
const CURVE_TOL: f64 = 1e-6;

/// A small map across the lower end of the gait's existence in stiffness (k near 480 N/m at c = 50).
fn spec() -> MapSpec {
    MapSpec {
        x: SweepSpec {
            param: "viscosity".into(),
            from: 30.0,
            to: 70.0,
            points: 5,
        },
        y: SweepSpec {
            param: "stiffness".into(),
            from: 440.0,
            to: 560.0,
            points: 4,
        },
    }
}

fn options() -> GaitOptions {
    GaitOptions {
        refine_jacobian: false,
        ..GaitOptions::default()
    }
}

/// The points as JSON: shortest round-trip numbers, so equal text is equal bits (and NaN, e.g. an unrefined
/// Jacobian's error, compares equal to itself as `null`).
fn same_bits(points: &[vrw::study::SweepPoint]) -> String {
    serde_json::to_string(points).unwrap()
}

/// Row j of a map is the 1-D sweep along x at y_j, bit for bit, and the curve points refined on that row are
/// the sweep's thresholds to the refinement tolerance; likewise a column against a sweep along y.
#[test]
fn map_rows_and_curves_agree_with_one_dimensional_sweeps() {
    let config = Config::default();
    let start = default_initial(&config);
    let spec = spec();
    let map = map_gaits(&config, &spec, &start, &options(), &|_| {}).unwrap();
    let curves = map_curves(&config, &map, &options(), DEFAULT_CURVE_COLUMNS).unwrap();
    assert!(
        curves.curves.iter().any(|c| c.name == "existence_end"),
        "{:?}",
        curves.curves
    );
    let mut checked = 0;
    for (along, line) in [(Along::X, 1), (Along::X, 2), (Along::Y, 2)] {
        let (line_config, line_spec) = match along {
            Along::X => {
                let mut c = config.clone();
                c.set_numeric("stiffness", map.ys[line]).unwrap();
                (c, spec.x.clone())
            }
            Along::Y => {
                let mut c = config.clone();
                c.set_numeric("viscosity", map.xs[line]).unwrap();
                (c, spec.y.clone())
            }
        };
        let points = sweep(&line_config, &line_spec, &start, &options(), &|_| {}).unwrap();
        if along == Along::X {
            assert_eq!(
                same_bits(&points),
                same_bits(&map.rows[line]),
                "row {line} of the map is the sweep along x"
            );
        }
        let mut expected: Vec<f64> = find_thresholds(
            Parameter::named(&line_config, &line_spec.param).unwrap(),
            &points,
            &options(),
        )
        .iter()
        .map(|t| t.value)
        .filter(|v| v.is_finite())
        .collect();
        expected.sort_by(f64::total_cmp);
        let coordinate = usize::from(along == Along::Y);
        let mut on_line: Vec<f64> = curves
            .curves
            .iter()
            .flat_map(|c| c.points.iter().zip(&c.refined_on))
            .filter(|(_, r)| r.along == along && r.line == line)
            .map(|(p, _)| p[coordinate])
            .collect();
        on_line.sort_by(f64::total_cmp);
        assert_eq!(
            on_line.len(),
            expected.len(),
            "{along:?} {line}: {on_line:?} vs {expected:?}"
        );
        for (a, b) in on_line.iter().zip(&expected) {
            assert!((a - b).abs() <= CURVE_TOL, "{along:?} {line}: {a} vs {b}");
        }
        checked += on_line.len();
    }
    assert!(checked > 0, "the lines checked cross a curve");
}

/// The map is the same for any number of threads.
#[test]
fn map_is_bitwise_identical_across_thread_counts() {
    let config = Config::default();
    let start = default_initial(&config);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| map_gaits(&config, &spec(), &start, &options(), &|_| {}).unwrap())
    };
    let (one, three) = (run(1), run(3));
    for (a, b) in one.rows.iter().zip(&three.rows) {
        assert_eq!(same_bits(a), same_bits(b));
    }
}

#[test]
fn map_rejects_bad_specifications() {
    let config = Config::default();
    let start = default_initial(&config);
    let base = spec();
    let mut same = base.clone();
    same.y.param = "viscosity".into();
    let mut unknown = base.clone();
    unknown.x.param = "foo".into();
    let mut one = base.clone();
    one.y.points = 1;
    let mut outside = base.clone();
    outside.y.from = -10.0;
    // A corner outside the domain although each axis alone is valid: L* < L0 at the corner.
    let mut corner = base.clone();
    corner.x = SweepSpec {
        param: "stopper_length".into(),
        from: 0.9,
        to: 1.1,
        points: 3,
    };
    corner.y = SweepSpec {
        param: "spring_natural_length".into(),
        from: 1.0,
        to: 1.2,
        points: 3,
    };
    for (what, s) in [
        ("same", same),
        ("unknown", unknown),
        ("one", one),
        ("outside", outside),
        ("corner", corner),
    ] {
        let e = map_gaits(&config, &s, &start, &options(), &|_| {});
        assert!(e.is_err(), "{what}");
    }
}

/// The threshold search takes the sweep's failed continuations as they are: clearing them (so every end is
/// followed afresh) gives the same thresholds, bit for bit.
#[test]
fn thresholds_reuse_the_sweeps_failed_continuations_exactly() {
    let config = Config::default();
    let spec = SweepSpec {
        param: "viscosity".into(),
        from: 120.0,
        to: 140.0,
        points: 5,
    };
    let start = default_initial(&config);
    let points = sweep(&config, &spec, &start, &options(), &|_| {}).unwrap();
    assert!(
        points.iter().any(|p| !p.attempts.is_empty()),
        "the sweep recorded the continuation that did not reach the point past the end"
    );
    let reused = find_thresholds(
        Parameter::named(&config, &spec.param).unwrap(),
        &points,
        &options(),
    );
    let mut cleared = points.clone();
    for p in &mut cleared {
        p.attempts.clear();
    }
    let afresh = find_thresholds(
        Parameter::named(&config, &spec.param).unwrap(),
        &cleared,
        &options(),
    );
    assert!(reused.iter().any(|t| t.name == "gait_lost"), "{reused:?}");
    assert_eq!(
        serde_json::to_string(&reused).unwrap(),
        serde_json::to_string(&afresh).unwrap()
    );
}

/// With fewer refined columns the curves still pass through every row's crossings, and the columns' crossings
/// are only on the refined columns.
#[test]
fn curves_on_fewer_columns_keep_every_row_crossing() {
    let config = Config::default();
    let start = default_initial(&config);
    let map = map_gaits(&config, &spec(), &start, &options(), &|_| {}).unwrap();
    let all = map_curves(&config, &map, &options(), DEFAULT_CURVE_COLUMNS).unwrap();
    let few = map_curves(&config, &map, &options(), 3).unwrap();
    let refined = vrw::study::map::curve_columns(map.xs.len(), 3);
    assert_eq!(refined, [0, 2, 4]);
    let rows = |c: &vrw::study::MapCurves| -> Vec<String> {
        c.thresholds
            .iter()
            .filter(|t| t.along == Along::X)
            .map(|t| serde_json::to_string(t).unwrap())
            .collect()
    };
    assert_eq!(rows(&all), rows(&few));
    assert!(few
        .thresholds
        .iter()
        .filter(|t| t.along == Along::Y)
        .all(|t| refined.contains(&t.line)));
    assert!(
        few.curves.iter().any(|c| c.points.len() > 1),
        "{:?}",
        few.curves
    );
    for r in few.curves.iter().flat_map(|c| &c.refined_on) {
        assert!(r.along == Along::X || refined.contains(&r.line), "{r:?}");
    }
}

/// The work and span of a map's phases ([`vrw::study::parallelism`]), in steps walked: the work is every step
/// the job walked (counted apart, by a meter around the whole job), the span at most the work, the tasks one per point and row (gaits), and all of it the same for 1, 2 and 3 threads.
#[test]
fn map_work_and_span_are_deterministic() {
    use vrw::meter::StepMeter;
    use vrw::study::map::{map_curves_measured, map_gaits_measured};
    use vrw::study::map_curves::continue_map_curves_measured;
    let config = Config::default();
    let start = default_initial(&config);
    let spec = spec();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let whole = StepMeter::new();
            let (map, gaits) = whole
                .run(|| map_gaits_measured(&config, &spec, 0..4, &start, &options(), &|_| {}))
                .unwrap();
            let gaits = gaits.work_span();
            assert_eq!(gaits.work_steps, whole.steps(), "{threads} threads");
            assert_eq!(gaits.tasks, 5 * 4 + 4);
            let crossings = StepMeter::new();
            let (mut curves, graph) = crossings
                .run(|| map_curves_measured(&config, &map, &options(), DEFAULT_CURVE_COLUMNS))
                .unwrap();
            let lines = graph.work_span();
            assert_eq!(lines.work_steps, crossings.steps(), "{threads} threads");
            let continued = StepMeter::new();
            let (_, graph) =
                continued.run(|| continue_map_curves_measured(&config, &map, &mut curves));
            let followed = graph.work_span();
            assert_eq!(followed.work_steps, continued.steps(), "{threads} threads");
            [gaits, lines, followed].map(|w| (w.tasks, w.work_steps, w.span_steps))
        })
    };
    let one = run(1);
    for (tasks, work, span) in one {
        assert!(span <= work && (tasks == 0) == (work == 0), "{one:?}");
    }
    // Gaits and crossings walk (this small map has no curve to continue).
    assert!(one[0].2 > 0 && one[1].2 > 0, "{one:?}");
    assert_eq!(run(2), one);
    assert_eq!(run(3), one);
}
