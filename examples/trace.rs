use vrw::{dynamics::Model, params::Config, walk::*};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut cfg = Config::default();
    let mut init = SectionState { l2: 0.72, theta_dot: 1.0, l2_dot: 0.0 };
    for a in &args[1..] { if let Some(v) = a.strip_prefix("init=") { let v: Vec<f64> = v.split(',').map(|x| x.parse().unwrap()).collect(); init = SectionState{l2:v[0],theta_dot:v[1],l2_dot:v[2]}; } else { cfg.apply_override(a).unwrap(); } }
    let model = Model::new(&cfg.params).unwrap();
    let mut tr = Trajectory::new(0.02);
    let run = simulate(&model, &cfg.solver, &init, 3, Some(&mut tr)).unwrap();
    let mut last = None;
    for s in &tr.samples {
        let a = (s.active.contact1, s.active.contact2, s.active.lock1, s.active.lock2);
        if Some(a) != last || true {
            println!("t={:.4} c1={} c2={} k1={} k2={} th={:.4} w={:.4} L1={:.4} L2={:.4} dL1={:.4} dL2={:.4} lam2={:.3} lam4={:.3} mu={:.3},{:.3}", s.time, a.0,a.1,a.2,a.3, s.q[2], s.qd[2], s.q[3], s.q[4], s.qd[3], s.qd[4], s.multipliers[1], s.multipliers[3], s.multipliers[4], s.multipliers[5]);
        }
        last = Some(a);
    }
    println!("{:?}", run.failure);
}
