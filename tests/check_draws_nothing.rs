//! `check` and `report` run for numbers: a log's check builds no scene (counted by the draw
//! stage's own counter, `draw::items_drawn`), and both commands refuse the same flags the same
//! way. One test in its own binary, so no other test draws while the counter is read.

use posecov::app::commands::{check, report};
use posecov::app::{AppError, Overrides};
use posecov::draw::items_drawn;

#[test]
fn check_and_report_of_a_log_draw_nothing_and_refuse_alike() {
    let before = items_drawn();
    let checked = check("covariance_health", &Overrides::default(), &[]).unwrap();
    assert_eq!(checked.exit_code(), 1, "{checked:?}");
    report("covariance_health", &Overrides::default(), true).unwrap();
    report("jackal_odometry", &Overrides::default(), false).unwrap();
    assert_eq!(
        items_drawn(),
        before,
        "check/report of a log built scene items"
    );

    // The counter counts: a plan's check draws (its line counts the drawn items).
    let plan = check("camera_on_robot", &Overrides::default(), &[]).unwrap();
    assert!(items_drawn() > before, "{plan:?}");

    // The same flag refused by both, with the same error (and so the same exit code).
    let too_many = Overrides {
        samples: Some(10_000_001),
        ..Default::default()
    };
    let by_check = check("camera_on_robot", &too_many, &[]).unwrap_err();
    let by_report = report("camera_on_robot", &too_many, true).unwrap_err();
    assert!(matches!(by_check, AppError::Settings(_)), "{by_check}");
    assert_eq!(by_check.to_string(), by_report.to_string());
    assert_eq!(by_check.exit_code(), by_report.exit_code());
}
