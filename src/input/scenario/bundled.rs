//! The scenarios shipped inside the binary (`assets/scenarios/*.toml`), one per lecture
//! illustration. A bundled scenario can be named instead of a path.

/// A scenario compiled into the binary.
#[derive(Debug, Clone, Copy)]
pub struct Bundled {
    /// Name (the file stem), e.g. `camera_on_robot`.
    pub name: &'static str,
    /// The file name, e.g. `camera_on_robot.toml`.
    pub file: &'static str,
    /// The TOML text.
    pub text: &'static str,
}

macro_rules! bundled {
    ($($name:literal),* $(,)?) => {
        /// Every bundled scenario, in teaching order.
        pub const BUNDLED: &[Bundled] = &[
            $(Bundled { name: $name, file: concat!($name, ".toml"), text: include_str!(concat!("../../../assets/scenarios/", $name, ".toml")) }),*
        ];
    };
}

bundled!(
    "camera_on_robot",
    "so3_sampling",
    "rotation_global_vs_local",
    "se3_global_vs_local",
    "ahrs_enu_to_map",
    "na568_se2_odometry",
    "na568_se3_odometry",
    "vector_space_vs_lie",
    "barfoot_compounding",
    "diff_drive_banana",
    "euler_vs_exp",
    "ros_pose_with_covariance",
);

/// The bundled scenario called `name` (with or without `.toml`).
///
/// ```
/// use posecov::input::scenario::bundled::find;
/// assert!(find("camera_on_robot").is_some());
/// assert!(find("camera_on_robot.toml").is_some());
/// assert!(find("nope").is_none());
/// ```
pub fn find(name: &str) -> Option<&'static Bundled> {
    let stem = name.strip_suffix(".toml").unwrap_or(name);
    BUNDLED.iter().find(|b| b.name == stem)
}
