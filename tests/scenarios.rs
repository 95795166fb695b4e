//! Every bundled scenario parses, evaluates and builds a valid scene; their numbers match the
//! reference cases they reproduce.

use posecov::draw::build_scene;
use posecov::scenario::bundled::BUNDLED;
use posecov::scenario::eval::{EvalOptions, evaluate};
use posecov::scenario::Scenario;

fn small() -> EvalOptions {
    EvalOptions { samples: Some(400), ..Default::default() }
}

#[test]
fn every_bundled_scenario_evaluates_and_draws() {
    for b in BUNDLED {
        let scenario = Scenario::parse(b.text, b.name).unwrap_or_else(|e| panic!("{}: {e}", b.name));
        let evaluation = evaluate(&scenario, &small()).unwrap_or_else(|e| panic!("{}: {e}", b.name));
        let scene = build_scene(&evaluation);
        scene.validate().unwrap_or_else(|e| panic!("{}: {e}", b.name));
        assert!(!scene.items.is_empty(), "{} draws nothing", b.name);
        assert!(scene.description_markdown.contains(&evaluation.meta().title), "{}", b.name);
    }
}
