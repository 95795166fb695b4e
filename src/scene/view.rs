//! The 3-D views of a scene: which part of the world each shows, what starts hidden, and where
//! its camera stands. Plain data, chosen by the drawing stage; the sink turns each into a Rerun
//! 3-D view with its eye controls and entity visibility in the blueprint.

use super::{QuatXyzw, SceneError, Vec3, WORLD, paths};

/// Rotates `v` by the unit quaternion `q` = `[x, y, z, w]`: v + 2w(u×v) + 2u×(u×v), u = (x, y, z).
///
/// ```
/// let s = std::f64::consts::FRAC_1_SQRT_2;
/// let r = posecov::scene::rotate(&[0.0, 0.0, s, s], [1.0, 0.0, 0.0]); // a quarter turn about z
/// assert!(r[0].abs() < 1e-12 && (r[1] - 1.0).abs() < 1e-12 && r[2].abs() < 1e-12);
/// ```
pub fn rotate(q: &QuatXyzw, v: Vec3) -> Vec3 {
    let (u, w) = ([q[0], q[1], q[2]], q[3]);
    let cross = |a: Vec3, b: Vec3| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let uv = cross(u, v);
    let uuv = cross(u, uv);
    [0, 1, 2].map(|i| v[i] + 2.0 * (w * uv[i] + uuv[i]))
}

/// A camera of a 3-D view: the eye at `position` looks at `target`, with the world direction
/// `up` pointing up on screen (it must not be parallel to the line of sight).
///
/// ```
/// use posecov::scene::Camera;
/// // Straight above the origin, x to the right and y up on screen.
/// let top = Camera { position: [0.0, 0.0, 5.0], target: [0.0; 3], up: [0.0, 1.0, 0.0] };
/// assert!(top.check("3D").is_ok());
/// let bad = Camera { up: [0.0, 0.0, 1.0], ..top };
/// assert!(bad.check("3D").is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Where the eye is, world frame (m).
    pub position: Vec3,
    /// The point it looks at (and orbits around), world frame (m).
    pub target: Vec3,
    /// The world direction shown as up on screen (any length > 0).
    pub up: Vec3,
}

impl Camera {
    /// Checks that every number is finite (also as `f32`), the eye is not at its target, and
    /// `up` is not parallel to the line of sight (within 0.5°). `view` names the view in
    /// errors.
    ///
    /// # Errors
    /// [`SceneError::BadCamera`] naming the view and the problem.
    pub fn check(&self, view: &str) -> Result<(), SceneError> {
        let bad = |reason: &'static str| {
            Err(SceneError::BadCamera {
                view: view.to_owned(),
                reason,
            })
        };
        let all = self.position.iter().chain(&self.target).chain(&self.up);
        if !all
            .into_iter()
            .all(|v| v.is_finite() && (*v as f32).is_finite())
        {
            return bad("a coordinate is not a finite number (as f32)");
        }
        let sight: Vec3 = [0, 1, 2].map(|i| self.target[i] - self.position[i]);
        let (s, u) = (norm(&sight), norm(&self.up));
        if s < 1e-6 {
            return bad("the eye is at its target");
        }
        if u == 0.0 {
            return bad("`up` is the zero vector");
        }
        let cos = (sight[0] * self.up[0] + sight[1] * self.up[1] + sight[2] * self.up[2]) / (s * u);
        if cos.abs() > (0.5f64).to_radians().cos() {
            return bad("`up` is parallel to the line of sight");
        }
        Ok(())
    }
}

fn norm(v: &Vec3) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Columns of the grid that holds `views` 3-D views side by side (⌈√n⌉; rows follow).
///
/// ```
/// assert_eq!([1, 2, 3, 4, 5].map(posecov::scene::grid_columns), [1, 2, 2, 2, 3]);
/// ```
pub fn grid_columns(views: usize) -> usize {
    (1..=views.max(1)).find(|c| c * c >= views).unwrap_or(1)
}

/// One 3-D view of the world.
///
/// The view shows every entity under each path of `include` (all of [`WORLD`] when empty) except
/// those under a path of `exclude`; entities under a path of `hidden` start hidden but stay in
/// the view's entity tree, one click away.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct View3d {
    /// The view's title, e.g. "3D" or "sigma points".
    pub name: String,
    /// Subtrees shown (entity paths under [`WORLD`]); empty: the whole world.
    pub include: Vec<String>,
    /// Subtrees left out of this view.
    pub exclude: Vec<String>,
    /// Subtrees shown but hidden at first (toggle them in the viewer's entity tree).
    pub hidden: Vec<String>,
    /// The camera; `None` leaves the viewer's automatic framing.
    pub camera: Option<Camera>,
    /// Metres between the lines of the ground grid (the plane z = 0) as the view opens, chosen
    /// with the camera so the viewer draws exactly this spacing there (it shows every tenth
    /// line only once the eye is about 80 spacings from the plane); the view says it in its
    /// title. `None`: the viewer's own (1 scene unit).
    pub grid_spacing: Option<f64>,
}

impl View3d {
    /// Whether an entity path is in this view (included and not excluded).
    ///
    /// ```
    /// use posecov::scene::View3d;
    /// let v = View3d { include: vec!["world/a".into()], exclude: vec!["world/a/x".into()], ..Default::default() };
    /// assert!(v.shows("world/a/y/cloud") && !v.shows("world/a/x/cloud") && !v.shows("world/ab"));
    /// ```
    pub fn shows(&self, path: &str) -> bool {
        let under = |root: &String| paths::is_under(path, root);
        (self.include.is_empty() || self.include.iter().any(under))
            && !self.exclude.iter().any(under)
    }

    /// Whether the view draws the entity at `path`: it [`shows`](Self::shows) it and does not
    /// hide it (a hidden entity stays in the view's tree, switched off).
    ///
    /// ```
    /// use posecov::scene::View3d;
    /// let v = View3d { hidden: vec!["world/a/x".into()], ..Default::default() };
    /// assert!(v.draws("world/a/y") && !v.draws("world/a/x/cloud") && v.shows("world/a/x/cloud"));
    /// ```
    pub fn draws(&self, path: &str) -> bool {
        self.shows(path) && !self.hidden.iter().any(|h| paths::is_under(path, h))
    }

    /// Checks the camera and that every path lies under [`WORLD`].
    ///
    /// # Errors
    /// [`SceneError::BadCamera`] or [`SceneError::WrongRoot`].
    pub fn check(&self) -> Result<(), SceneError> {
        for path in self.include.iter().chain(&self.exclude).chain(&self.hidden) {
            let under_world = paths::is_under(path, WORLD);
            if !under_world {
                return Err(SceneError::WrongRoot {
                    path: path.clone(),
                    kind: "3-D view subtree",
                    root: WORLD,
                });
            }
        }
        if let Some(s) = self.grid_spacing
            && !(s.is_finite() && s > 0.0 && (s as f32).is_normal())
        {
            return Err(SceneError::BadCamera {
                view: self.name.clone(),
                reason: "the grid spacing is not a positive number (as f32)",
            });
        }
        self.camera.map_or(Ok(()), |c| c.check(&self.name))
    }

    /// The view's title as shown: its name and, when it has one, its grid spacing
    /// ("3D · grid 0.5 m").
    ///
    /// ```
    /// use posecov::scene::View3d;
    /// let v = View3d { name: "3D".into(), grid_spacing: Some(0.5), ..Default::default() };
    /// assert_eq!(v.title(), "3D · grid 0.5 m");
    /// ```
    pub fn title(&self) -> String {
        match self.grid_spacing {
            Some(s) => format!("{} · grid {}", self.name, super::units::length_label(s)),
            None => self.name.clone(),
        }
    }
}
