//! Optimises a g2o / GTSAM pose graph and computes every pose's marginal, printing one JSON
//! line of timings and sizes (the Rust side of `benches/run_gtsam.sh`; run it under
//! `/usr/bin/time -v` for the peak memory).
//!
//! `cargo run --release --no-default-features --example graph_bench -- FILE [g2o|gtsam] [lm|gn]`

use std::time::Instant;

use posecov::eval::graph::{GraphReading, Optimizer, SolverSettings, optimize};
use posecov::input::graph::read_file;
use posecov::plan::AnyPlan;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .ok_or("usage: graph_bench FILE [g2o|gtsam] [lm|gn]")?;
    let reading = match args.get(1).map(String::as_str) {
        Some("gtsam") => GraphReading::Gtsam,
        _ => GraphReading::G2o,
    };
    let optimizer = match args.get(2).map(String::as_str) {
        Some("gn") => Optimizer::GaussNewton,
        _ => Optimizer::LevenbergMarquardt,
    };
    let settings = SolverSettings {
        reading,
        optimizer,
        ..SolverSettings::default()
    };
    let clock = Instant::now();
    let (_, input) = read_file(std::path::Path::new(path))?;
    let read_seconds = clock.elapsed().as_secs_f64();
    macro_rules! run {
        ($graph:expr) => {{
            let graph = $graph.ok_or("no graph")?;
            let s = optimize(&graph, &settings, &mut |_| {})?;
            let marginals = s.covariances.iter().filter(|c| c.is_some()).count();
            println!(
                "{{\"file\": {path:?}, \"poses\": {}, \"edges\": {}, \"read_s\": {read_seconds:.4}, \"optimize_s\": {:.4}, \"marginals_s\": {:.4}, \"iterations\": {}, \"stop\": \"{:?}\", \"chi2_before\": {:.6e}, \"chi2_after\": {:.6e}, \"marginals\": {marginals}, \"unknowns\": {}, \"factor_nonzeros\": {}}}",
                graph.vertices.len(),
                graph.edges.len(),
                s.optimize_seconds,
                s.marginals_seconds,
                s.iterations,
                s.stop,
                s.chi2_before,
                s.chi2_after,
                s.unknowns,
                s.factor_nonzeros
            );
        }};
    }
    match input.plan {
        AnyPlan::Se2(p) => run!(p.graph),
        AnyPlan::Se3(p) => run!(p.graph),
        _ => return Err("not a pose graph".into()),
    }
    Ok(())
}
