//! Tests of the table declarations: every table is written and read back by column name, the readers of
//! [`crate::output::read`] name their fields as the declarations do and hold the quantities those names say,
//! and a column name that appears in several tables means the same quantity in each (so two columns whose
//! accessors are swapped in one declaration fail).

use std::collections::BTreeMap;
use std::path::Path;

use super::attractors::{orbit_columns, OrbitRow, BASIN, BRANCH};
use super::map::{map_columns, MapPoint};
use super::steps::{StepsColumns, STEPS};
use super::sweep::{FRICTION_GAIT_COLUMNS, SWEEP};
use super::trajectory::{SWING_COLUMNS, TRAJECTORY};
use super::*;
use crate::dynamics::Model;
use crate::gait::{find_gait_any_period, Gait, GaitOptions, StepMap, MAX_PERIOD};
use crate::output::read::{read_csv, StepRow, TrajectoryRow};
use crate::output::{
    step_row, sweep_header, sweep_row, trajectory_row, write_basin_csv, write_branch_csv,
    write_map_csv, write_orbit_csv, write_steps_csv, write_sweep_csv, write_trajectory_csv,
    STEPS_HEADER, SWEEP_COLUMNS, TRAJECTORY_HEADER,
};
use crate::params::{Config, Params, RearExit};
use crate::reference::default_initial;
use crate::study::basin::{BasinPoint, Outcome, OutcomeKind};
use crate::study::orbit::OrbitColumn;
use crate::study::{GaitMap, MapSpec, PointStatus, SweepPoint, SweepSpec};
use crate::walk::{simulate, Sample, SectionState, StepReport, Trajectory};

/// A short walk with its trajectory, and the gait of the default parameters.
struct Fixture {
    steps: Vec<StepReport>,
    samples: Vec<Sample>,
    gait: Gait,
}

fn fixture() -> Fixture {
    let config = Config::default();
    let model = Model::new(&config.params).unwrap();
    let start = default_initial(&config);
    let mut trajectory = Trajectory::new(0.1);
    let run = simulate(&model, &config.solver, &start, 3, Some(&mut trajectory)).unwrap();
    let map = StepMap::new(&model, &config.solver);
    let gait = find_gait_any_period(&map, &start, &GaitOptions::default(), MAX_PERIOD).unwrap();
    Fixture {
        steps: run.steps,
        samples: trajectory.samples,
        gait,
    }
}

/// A sweep point with the gait, and one without.
fn sweep_points(gait: &Gait) -> [SweepPoint; 2] {
    let found = SweepPoint {
        value: 50.0,
        status: PointStatus::Gait(gait.stability),
        message: None,
        gait: Some(gait.clone()),
        continued_from: None,
        family: Some(3),
        attempts: Vec::new(),
    };
    let lost = SweepPoint {
        value: 60.0,
        status: PointStatus::NoGait("rolled_back"),
        message: Some("rolled back".to_string()),
        gait: None,
        continued_from: None,
        family: None,
        attempts: Vec::new(),
    };
    [found, lost]
}

/// Does the CSV field `text` hold `cell`, as [`Cell::to_csv`] writes it? (Reals read back equal, and
/// [`num`](crate::output::num) writes `-0` as `0`.)
fn holds(text: &str, cell: &Cell) -> bool {
    match cell {
        Cell::Real(v) => text
            .parse::<f64>()
            .is_ok_and(|r| r == *v || (r.is_nan() && v.is_nan())),
        Cell::Count(n) => text.parse::<usize>() == Ok(*n),
        Cell::Flag(b) => text.parse::<bool>() == Ok(*b),
        Cell::Text(t) => text == t,
        Cell::Empty => text.is_empty(),
    }
}

/// Read `path` back and check, by column name, that every row holds what the declared accessors give for the
/// items written (the header is also the declared one, in order).
fn check_by_name<T>(path: &Path, columns: &[Column<T>], params: &[&str], items: &[T]) {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let names: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(names, header(columns, params), "{}", path.display());
    let records: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    assert_eq!(records.len(), items.len(), "{}", path.display());
    for column in columns {
        let name = column.header_name(params);
        let at = names.iter().position(|n| n == name).unwrap();
        for (k, (record, item)) in records.iter().zip(items).enumerate() {
            let cell = (column.get)(item);
            assert!(
                holds(&record[at], &cell),
                "{} row {}: {name} is {:?}, its accessor gives {cell:?}",
                path.display(),
                k + 1,
                &record[at]
            );
        }
    }
}

/// The declared names of a table are unique (a reader finds a column by its name), and every column says
/// what it holds.
fn assert_unique<T>(table: &str, columns: &[Column<T>], params: &[&str]) {
    let names = header(columns, params);
    for (k, name) in names.iter().enumerate() {
        assert!(!names[..k].contains(name), "{table}: {name} twice");
        assert!(!columns[k].doc.is_empty(), "{table}: {name} has no doc");
    }
}

/// Every row function gives one cell per header name (the CSV writers and the Python binding rely on it).
#[test]
fn rows_match_their_headers() {
    let f = fixture();
    assert_eq!(step_row(&f.steps[0]).len(), STEPS_HEADER.len());
    assert_eq!(trajectory_row(&f.samples[0]).len(), TRAJECTORY_HEADER.len());
    for p in sweep_points(&f.gait) {
        for friction in [false, true] {
            assert_eq!(
                sweep_row(&p, friction).len(),
                sweep_header("c", friction).len()
            );
        }
    }
    assert_eq!(Cell::Empty.to_csv(), "");
    assert_eq!(Cell::Real(f64::NAN).to_csv(), "NaN");
}

/// The names the Python binding keys its dicts by (`STEPS_HEADER`, `TRAJECTORY_HEADER`, `sweep_header`) are
/// the declared ones, and every table's names are unique.
#[test]
fn python_names_are_the_declared_ones() {
    assert_eq!(STEPS_HEADER.to_vec(), header(&STEPS, &[]));
    assert_eq!(TRAJECTORY_HEADER.to_vec(), header(&TRAJECTORY, &[]));
    assert_eq!(
        sweep_header("viscosity", false),
        header(&SWEEP, &["viscosity"])
    );
    assert_eq!(sweep_header("viscosity", false)[1..], SWEEP_COLUMNS);
    assert_eq!(
        sweep_header("viscosity", true)[1 + SWEEP_COLUMNS.len()..],
        header(&FRICTION_GAIT_COLUMNS, &[])
    );
    assert_unique("friction columns", &FRICTION_GAIT_COLUMNS, &[]);
    // vrw continue's branch.csv: the slip velocity last, with friction only.
    let family = crate::output::family_header("viscosity", false);
    let with_slip = crate::output::family_header("viscosity", true);
    assert_eq!(with_slip[..family.len()], family[..]);
    assert_eq!(with_slip[family.len()..], ["slip"]);
    assert!(!family.contains(&"slip"));
    assert_unique("steps.csv", &STEPS, &[]);
    assert_unique("trajectory.csv", &TRAJECTORY, &[]);
    assert_unique("sweep.csv", &SWEEP, &["c"]);
    assert_unique("map.csv", &map_columns(), &["c", "k"]);
    assert_unique("orbit.csv", &orbit_columns(), &["c"]);
    assert_unique("branch.csv", &BRANCH, &["c"]);
    assert_unique("basin.csv", &BASIN, &[]);
}

/// Every table, written by its writer, reads back under each declared name what that column's accessor gave.
#[test]
fn every_table_reads_back_by_name() {
    let f = fixture();
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name);

    write_steps_csv(
        &path("steps.csv"),
        &f.steps,
        StepsColumns::of(&Params::default()),
    )
    .unwrap();
    check_by_name(&path("steps.csv"), &STEPS, &[], &f.steps);
    write_trajectory_csv(&path("trajectory.csv"), &f.samples, RearExit::Relock).unwrap();
    check_by_name(&path("trajectory.csv"), &TRAJECTORY, &[], &f.samples);

    let points = sweep_points(&f.gait);
    write_sweep_csv(&path("sweep.csv"), "viscosity", false, &points).unwrap();
    check_by_name(&path("sweep.csv"), &SWEEP, &["viscosity"], &points);

    let axis = |param: &str| SweepSpec {
        param: param.to_string(),
        from: 1.0,
        to: 2.0,
        points: 2,
    };
    let map = GaitMap {
        spec: MapSpec {
            x: axis("viscosity"),
            y: axis("stiffness"),
        },
        xs: vec![50.0, 60.0],
        ys: vec![500.0, 550.0],
        rows: vec![points.to_vec(), points.iter().rev().cloned().collect()],
    };
    write_map_csv(&path("map.csv"), &map, false).unwrap();
    let map_points: Vec<MapPoint> = map
        .rows
        .iter()
        .zip(&map.ys)
        .flat_map(|(row, &y)| row.iter().map(move |point| MapPoint { y, point }))
        .collect();
    let params = ["viscosity", "stiffness"];
    check_by_name(&path("map.csv"), &map_columns(), &params, &map_points);

    let walked = OrbitColumn {
        value: 50.0,
        status: crate::study::orbit::WalkStatus::Walking,
        message: None,
        returns: f.steps.clone(),
        period_k: Some(1),
        continued_from: Some(40.0),
    };
    let failed = OrbitColumn {
        value: 60.0,
        status: crate::study::orbit::WalkStatus::Failed("fell"),
        message: Some("fell".to_string()),
        returns: Vec::new(),
        period_k: None,
        continued_from: None,
    };
    let diagram = [walked, failed];
    write_orbit_csv(&path("orbit.csv"), "viscosity", false, &diagram).unwrap();
    let mut orbit_rows: Vec<OrbitRow> = (diagram[0].returns.iter().enumerate())
        .map(|(n, s)| OrbitRow {
            column: &diagram[0],
            step: Some((n + 1, s)),
        })
        .collect();
    orbit_rows.push(OrbitRow {
        column: &diagram[1],
        step: None,
    });
    check_by_name(
        &path("orbit.csv"),
        &orbit_columns(),
        &["viscosity"],
        &orbit_rows,
    );

    let branch = [(50.0, Some(f.gait.clone())), (60.0, None)];
    write_branch_csv(&path("branch.csv"), "viscosity", false, &branch).unwrap();
    check_by_name(&path("branch.csv"), &BRANCH, &["viscosity"], &branch);

    let start = SectionState::from_array([0.7, 1.0, -0.2]);
    let point = |ix, end: Option<SectionState>, kind: OutcomeKind| BasinPoint {
        ix,
        iy: 1,
        start,
        outcome: Outcome {
            kind,
            steps: 7,
            period_k: end.map(|_| 2),
            end,
        },
    };
    let grid = vec![vec![
        point(0, Some(f.gait.section), OutcomeKind::Other),
        point(1, None, OutcomeKind::Failed("fell")),
    ]];
    write_basin_csv(&path("basin.csv"), false, &grid).unwrap();
    check_by_name(&path("basin.csv"), &BASIN, &[], &grid[0]);
}

/// What a reader of [`crate::output::read`] holds under each column name (its serde names), as JSON.
fn fields_by_name<R: serde::Serialize>(row: &R) -> serde_json::Map<String, serde_json::Value> {
    match serde_json::to_value(row).unwrap() {
        serde_json::Value::Object(map) => map,
        other => panic!("not a struct: {other}"),
    }
}

/// Does the value a reader read equal `cell`? (A flag may be read as a bool from a `0`/`1` count.)
fn reads_as(value: &serde_json::Value, cell: &Cell) -> bool {
    use serde_json::Value;
    match (cell, value) {
        (Cell::Real(v), Value::Number(n)) => n.as_f64() == Some(*v),
        (Cell::Real(v), Value::Null) => v.is_nan(),
        (Cell::Count(c), Value::Number(n)) => n.as_u64() == Some(*c as u64),
        (Cell::Count(c), Value::Bool(b)) => *c == usize::from(*b),
        (Cell::Flag(f), Value::Bool(b)) => f == b,
        (Cell::Text(t), Value::String(s)) => t == s,
        _ => false,
    }
}

/// Every field of the readers `StepRow` and `TrajectoryRow` is named after a declared column of its table and
/// reads back what that column's accessor wrote, with the column's kind (a reader field named after a column
/// that is not declared, or of another kind, fails; [`readers_hold_the_named_quantities`] checks that each
/// field holds the quantity its name says).
#[test]
fn readers_follow_the_declarations() {
    fn check<T, R: serde::Serialize>(file: &str, tables: &[&[Column<T>]], items: &[T], read: &[R]) {
        assert_eq!(items.len(), read.len(), "{file}");
        for (item, row) in items.iter().zip(read) {
            for (name, value) in fields_by_name(row) {
                let column = tables
                    .iter()
                    .flat_map(|columns| columns.iter())
                    .find(|c| matches!(c.name, Name::Fixed(n) if n == name))
                    .unwrap_or_else(|| {
                        panic!("{file}: the reader's {name} is not a declared column")
                    });
                let cell = (column.get)(item);
                assert!(
                    reads_as(&value, &cell),
                    "{file}: {name} reads {value}, was {cell:?}"
                );
            }
        }
    }
    let f = fixture();
    let dir = tempfile::tempdir().unwrap();
    let steps_path = dir.path().join("steps.csv");
    write_steps_csv(&steps_path, &f.steps, StepsColumns::of(&Params::default())).unwrap();
    let steps: Vec<StepRow> = read_csv(&steps_path, false).unwrap();
    check("steps.csv", &[&STEPS], &f.steps, &steps);
    let trajectory_path = dir.path().join("trajectory.csv");
    // With the swinging leg's columns (rear_exit = continue), which the reader reads too.
    write_trajectory_csv(&trajectory_path, &f.samples, RearExit::Continue).unwrap();
    let samples: Vec<TrajectoryRow> = read_csv(&trajectory_path, false).unwrap();
    check(
        "trajectory.csv",
        &[&TRAJECTORY, &SWING_COLUMNS],
        &f.samples,
        &samples,
    );
}

/// The readers' fields hold the quantities their names say, checked against the walk's own fields (so two
/// columns whose accessors were swapped in a declaration fail).
#[test]
fn readers_hold_the_named_quantities() {
    let f = fixture();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("trajectory.csv");
    write_trajectory_csv(&path, &f.samples, RearExit::Relock).unwrap();
    let rows: Vec<TrajectoryRow> = read_csv(&path, false).unwrap();
    for (s, r) in f.samples.iter().zip(&rows) {
        let q = [r.x, r.z, r.theta, r.l1, r.l2];
        assert_eq!(q, [s.q[0], s.q[1], s.q[2], s.q[3], s.q[4]]);
        assert_eq!(
            [r.theta_dot, r.l1_dot, r.l2_dot],
            [s.qd[2], s.qd[3], s.qd[4]]
        );
        let m = &s.multipliers;
        assert_eq!(
            [r.lambda_1, r.lambda_2, r.lambda_3, r.lambda_4],
            [m[0], m[1], m[2], m[3]]
        );
        let a = &s.active;
        assert_eq!(
            [r.contact1, r.contact2, r.slide1, r.slide2],
            [a.contact1, a.contact2, a.slide1, a.slide2]
        );
        let held = |lock: bool, compression: bool| u8::from(lock) + 2 * u8::from(compression);
        assert_eq!(
            [r.lock1, r.lock2],
            [held(a.lock1, a.compression1), held(a.lock2, a.compression2)]
        );
        assert_eq!((r.time, r.leg1), (s.time, s.leg1));
    }
    let path = dir.path().join("steps.csv");
    write_steps_csv(&path, &f.steps, StepsColumns::of(&Params::default())).unwrap();
    let rows: Vec<StepRow> = read_csv(&path, false).unwrap();
    for (s, r) in f.steps.iter().zip(&rows) {
        let i = &s.indicators;
        assert_eq!(
            [r.lambda_i4, r.lambda_2_plus, r.lambda_4_plus],
            [i.lambda_i4, i.lambda_2_plus, i.lambda_4_plus]
        );
        let e = &s.energy;
        assert_eq!(
            [
                r.energy_loss,
                r.damper_loss,
                r.impact_loss,
                r.stopper_loss,
                r.energy_residual
            ],
            [e.loss, e.damper, e.impact, e.stopper, e.residual]
        );
        assert_eq!(
            [r.time, r.dls_duration, r.period],
            [s.time, s.dls_duration, s.period]
        );
        assert_eq!(
            (r.step, r.branch.as_str()),
            (s.step, s.branch.to_string().as_str())
        );
    }
}

/// A column name that appears in several tables means the same quantity in each: the gait's row of
/// `sweep.csv`, `map.csv` and `branch.csv` and its step's row of `steps.csv` and `orbit.csv` agree on every
/// name they share.
#[test]
fn shared_names_mean_the_same_quantity() {
    let f = fixture();
    let step = &f.gait.cycle[0];
    let [found, _] = sweep_points(&f.gait);
    let column = OrbitColumn {
        value: 50.0,
        status: crate::study::orbit::WalkStatus::Walking,
        message: None,
        returns: vec![*step],
        period_k: Some(1),
        continued_from: None,
    };
    let params = ["viscosity", "stiffness"];
    let named = |names: Vec<&str>, cells: Vec<Cell>| -> BTreeMap<String, Cell> {
        names.into_iter().map(String::from).zip(cells).collect()
    };
    let tables = [
        ("steps.csv", named(header(&STEPS, &[]), row(&STEPS, step))),
        (
            "sweep.csv",
            named(header(&SWEEP, &params), row(&SWEEP, &found)),
        ),
        (
            "map.csv",
            named(
                header(&map_columns(), &params),
                row(
                    &map_columns(),
                    &MapPoint {
                        y: 1.0,
                        point: &found,
                    },
                ),
            ),
        ),
        (
            "orbit.csv",
            named(
                header(&orbit_columns(), &params),
                row(
                    &orbit_columns(),
                    &OrbitRow {
                        column: &column,
                        step: Some((1, step)),
                    },
                ),
            ),
        ),
        (
            "branch.csv",
            named(
                header(&BRANCH, &params),
                row(&BRANCH, &(50.0, Some(f.gait.clone()))),
            ),
        ),
    ];
    // Names whose meaning differs by design: the start of `basin.csv` is not in these tables, `status` and
    // `period_k` are the outcome of a sweep point or of an orbit column, `step` and `time` belong to a walk.
    let own = [
        "viscosity",
        "stiffness",
        "status",
        "step",
        "time",
        "message",
    ];
    let mut shared = 0;
    for (k, (a, first)) in tables.iter().enumerate() {
        for (b, second) in &tables[k + 1..] {
            for (name, cell) in first {
                if let Some(other) = second.get(name).filter(|_| !own.contains(&name.as_str())) {
                    assert_eq!(cell, other, "{name} in {a} and {b}");
                    shared += 1;
                }
            }
        }
    }
    assert!(shared > 30, "only {shared} shared cells compared");
}
