//! The bundled robot logs (`posecov list`): a real ROS 1 bag and a generated MCAP file, built
//! into the binary so a newcomer can try them with no file.

use crate::input::{Example, Format};

/// A bundled log: its name, the file name it is shown under, its format, bytes and title.
#[derive(Debug, Clone, Copy)]
pub struct BundledLog {
    /// What `posecov NAME` takes.
    pub name: &'static str,
    /// File name in messages.
    pub file: &'static str,
    /// Its format.
    pub format: Format,
    /// One-line title for `posecov list`.
    pub title: &'static str,
    /// The file's bytes.
    pub bytes: &'static [u8],
}

/// Every bundled log.
pub const LOGS: [BundledLog; 2] = [
    BundledLog {
        name: "jackal_odometry",
        file: "test2.bag",
        format: Format::Ros1Bag,
        title: "A Jackal's wheel odometry (robot_localization's test2.bag): 1e6 placeholders, planar",
        bytes: include_bytes!("../../../tests/data/robot_localization/test2.bag"),
    },
    BundledLog {
        name: "covariance_health",
        file: "health_cases.mcap",
        format: Format::Mcap,
        title: "Every covariance health case on a planar Odometry and a 3-D PoseWithCovarianceStamped topic",
        bytes: include_bytes!("../../../tests/data/mcap/health_cases.mcap"),
    },
];

/// The bundled log named `name` (or by its file name).
///
/// ```
/// assert_eq!(posecov::input::log::bundled::find("jackal_odometry").unwrap().file, "test2.bag");
/// assert!(posecov::input::log::bundled::find("nope").is_none());
/// ```
pub fn find(name: &str) -> Option<&'static BundledLog> {
    LOGS.iter().find(|l| l.name == name || l.file == name)
}

/// The bundled logs as [`Example`]s (no text: they are binary; `posecov list` takes their
/// titles from [`find`]).
///
/// ```
/// use posecov::input::Format;
/// let formats: Vec<Format> = posecov::input::log::bundled::examples().map(|e| e.format).collect();
/// assert_eq!(formats, [Format::Ros1Bag, Format::Mcap]);
/// ```
pub fn examples() -> impl Iterator<Item = Example> {
    LOGS.iter().map(|l| Example {
        name: l.name,
        format: l.format,
        file: l.file,
        text: "",
    })
}
