//! The pose graphs shipped inside the binary: two of GTSAM's example graphs (BSD licence, see
//! `tests/data/gtsam/SOURCE.md`), one planar and one 3D, so a newcomer can try the format
//! with no file.

use crate::input::{Example, Format};

/// Every bundled graph: `(name, file name, text)`.
pub const BUNDLED: &[(&str, &str, &str)] = &[
    (
        "gtsam_pose2example",
        "gtsam_pose2example.txt",
        include_str!("../../../tests/data/gtsam/pose2example.txt"),
    ),
    (
        "gtsam_pose3example",
        "gtsam_pose3example.txt",
        include_str!("../../../tests/data/gtsam/pose3example.txt"),
    ),
];

/// The bundled graphs as examples.
///
/// ```
/// assert_eq!(posecov::input::graph::bundled::examples().count(), 2);
/// ```
pub fn examples() -> impl Iterator<Item = Example> {
    BUNDLED.iter().map(|&(name, file, text)| Example {
        name,
        format: Format::Graph,
        file,
        text,
    })
}
