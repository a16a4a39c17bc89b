//! What an evaluator is built from ([`Input`]: a triangle mesh, an oriented point cloud, a Bézier
//! patch set or a trimmed STEP model), and [`load_input`], which reads any of them from a file,
//! deciding what the file holds once (by extension, then by content).
//!
//! ```
//! use gwn::input::{Input, InputKind};
//! use gwn::mesh::Mesh;
//! let tet = Mesh::from_slices(
//!     &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
//!     &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
//! )?;
//! let input = Input::Mesh(tet);
//! assert_eq!(input.kind(), InputKind::Mesh);
//! assert_eq!(input.bounding_box().unwrap().max, [1.0, 1.0, 1.0]);
//! # Ok::<(), gwn::error::MeshError>(())
//! ```

use std::fmt;

use crate::base::bounding_box::BoundingBox;
use crate::mesh::{Mesh, PointCloud};
#[cfg(feature = "patch")]
use crate::patch::PatchSet;
#[cfg(all(feature = "patch", feature = "io"))]
use crate::patch::step::StepModel;

/// Anything the library evaluates the winding number of.
#[derive(Clone, Debug)]
pub enum Input {
    /// A triangle mesh (or soup).
    Mesh(Mesh),
    /// An oriented point cloud.
    Cloud(PointCloud),
    /// A set of (rational) Bézier patches (`.bpt`, `.rbpt`; feature `patch`).
    #[cfg(feature = "patch")]
    Patches(PatchSet),
    /// A trimmed B-rep model (`.step`, `.stp`; features `patch` and `io`); boxed, it is much
    /// larger than the others.
    #[cfg(all(feature = "patch", feature = "io"))]
    Step(Box<StepModel>),
}

/// What an [`Input`] is, without its data (for messages and method choices).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum InputKind {
    /// [`Input::Mesh`].
    Mesh,
    /// [`Input::Cloud`].
    Cloud,
    /// `Input::Patches` (feature `patch`).
    Patches,
    /// `Input::Step` (features `patch` and `io`).
    Step,
}

impl fmt::Display for InputKind {
    /// With its article, to complete a sentence: "a triangle mesh", "a point cloud", ...
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            InputKind::Mesh => "a triangle mesh",
            InputKind::Cloud => "a point cloud",
            InputKind::Patches => "a patch set",
            InputKind::Step => "a STEP model",
        })
    }
}

impl Input {
    /// What this input is.
    pub fn kind(&self) -> InputKind {
        match self {
            Input::Mesh(_) => InputKind::Mesh,
            Input::Cloud(_) => InputKind::Cloud,
            #[cfg(feature = "patch")]
            Input::Patches(_) => InputKind::Patches,
            #[cfg(all(feature = "patch", feature = "io"))]
            Input::Step(_) => InputKind::Step,
        }
    }

    /// The bounding box of the triangles, points or control points; `None` when there are none.
    pub fn bounding_box(&self) -> Option<BoundingBox> {
        match self {
            Input::Mesh(m) => m.bounding_box(),
            Input::Cloud(c) => BoundingBox::of_points(c.positions()),
            #[cfg(feature = "patch")]
            Input::Patches(p) => {
                let (min, max) = p.bounding_box();
                Some(BoundingBox { min, max })
            }
            #[cfg(all(feature = "patch", feature = "io"))]
            Input::Step(m) => {
                let (min, max) = m.bounding_box();
                Some(BoundingBox { min, max })
            }
        }
    }

    /// The triangle mesh, when this is one.
    pub fn mesh(&self) -> Option<&Mesh> {
        match self {
            Input::Mesh(m) => Some(m),
            _ => None,
        }
    }
}

#[cfg(feature = "io")]
pub use loading::{InputError, LoadedInput, load_input, load_input_with};

#[cfg(feature = "io")]
mod loading {
    use std::fmt;
    use std::path::Path;

    use super::Input;
    use crate::error::{LoadError, LoadWarning};
    use crate::io::{LoadOptions, MeshOrCloud};
    #[cfg(feature = "patch")]
    use crate::patch::{PatchError, step::StepError};

    /// An input as loaded, with what the reader accepted but ignored.
    #[derive(Clone, Debug)]
    pub struct LoadedInput {
        /// What the file holds.
        pub input: Input,
        /// What the reader ignored (e.g. unknown PLY header lines); empty for patch sets and
        /// STEP models.
        pub warnings: Vec<LoadWarning>,
    }

    /// Why a file could not be loaded as an [`Input`]. Displays as one line naming the file.
    #[derive(Debug)]
    pub enum InputError {
        /// A mesh or point-cloud file.
        Load(LoadError),
        /// A patch file.
        #[cfg(feature = "patch")]
        Patch(PatchError),
        /// A STEP file.
        #[cfg(feature = "patch")]
        Step(StepError),
    }

    impl fmt::Display for InputError {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            match self {
                InputError::Load(e) => e.fmt(f),
                #[cfg(feature = "patch")]
                InputError::Patch(e) => e.fmt(f),
                #[cfg(feature = "patch")]
                InputError::Step(e) => e.fmt(f),
            }
        }
    }

    impl std::error::Error for InputError {
        fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
            match self {
                InputError::Load(e) => Some(e),
                #[cfg(feature = "patch")]
                InputError::Patch(e) => Some(e),
                #[cfg(feature = "patch")]
                InputError::Step(e) => Some(e),
            }
        }
    }

    /// [`load_input_with`] with the default [`LoadOptions`].
    pub fn load_input(path: impl AsRef<Path>) -> Result<LoadedInput, InputError> {
        load_input_with(path, &LoadOptions::default())
    }

    /// Loads whatever `path` holds, deciding once:
    /// - `.bpt`, `.rbpt`: a patch set (`gwn::patch::load_patches`; feature `patch`);
    /// - `.step`, `.stp`: a trimmed model (`gwn::patch::step::load_step`; feature `patch`);
    /// - `.xyz`, `.xyzn`, `.csv`, `.txt`, `.pts`: an oriented point cloud (text columns);
    /// - a PLY (by extension, or by content without one): read once, a mesh when it has faces,
    ///   else an oriented point cloud (its vertices must then have normals);
    /// - anything else: a mesh ([`crate::io::load_mesh_with`], welded as `options` say).
    ///
    /// ```
    /// use gwn::input::{Input, load_input};
    /// let dir = std::env::temp_dir().join(format!("gwn-doc-load-input-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// let (mesh, cloud) = (dir.join("tri.ply"), dir.join("pts.ply"));
    /// let header = "ply\nformat ascii 1.0\nelement vertex 3\n\
    ///               property float x\nproperty float y\nproperty float z\n";
    /// std::fs::write(&mesh, format!("{header}element face 1\n\
    ///     property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"))?;
    /// std::fs::write(&cloud, "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n\
    ///     property float y\nproperty float z\nproperty float nx\nproperty float ny\n\
    ///     property float nz\nend_header\n0 0 0 0 0 1\n")?;
    /// assert!(matches!(load_input(&mesh)?.input, Input::Mesh(_)));
    /// assert!(matches!(load_input(&cloud)?.input, Input::Cloud(_)));
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn load_input_with(
        path: impl AsRef<Path>,
        options: &LoadOptions,
    ) -> Result<LoadedInput, InputError> {
        let path = path.as_ref();
        #[cfg(feature = "patch")]
        if let Some(curved) = load_curved(path)? {
            return Ok(LoadedInput {
                input: curved,
                warnings: Vec::new(),
            });
        }
        Ok(
            match crate::io::load_mesh_or_cloud(path, options).map_err(InputError::Load)? {
                MeshOrCloud::Mesh(loaded) => LoadedInput {
                    input: Input::Mesh(loaded.mesh),
                    warnings: loaded.warnings,
                },
                MeshOrCloud::Cloud(cloud, warnings) => LoadedInput {
                    input: Input::Cloud(cloud),
                    warnings,
                },
            },
        )
    }

    /// A patch set or STEP model, when the extension names one.
    #[cfg(feature = "patch")]
    fn load_curved(path: &Path) -> Result<Option<Input>, InputError> {
        if crate::patch::is_patch_path(path) {
            let set = crate::patch::load_patches(path).map_err(InputError::Patch)?;
            return Ok(Some(Input::Patches(set)));
        }
        if crate::patch::step::is_step_path(path) {
            let model = crate::patch::step::load_step(path).map_err(InputError::Step)?;
            return Ok(Some(Input::Step(Box::new(model))));
        }
        Ok(None)
    }
}

#[cfg(all(test, feature = "io"))]
mod tests {
    use super::*;

    /// A scratch directory removed on drop.
    struct Scratch(std::path::PathBuf);

    impl Scratch {
        fn new(name: &str) -> Scratch {
            let dir = std::env::temp_dir().join(format!("gwn-input-{name}-{}", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            Scratch(dir)
        }
        fn file(&self, name: &str, bytes: &[u8]) -> std::path::PathBuf {
            let p = self.0.join(name);
            std::fs::write(&p, bytes).unwrap();
            p
        }
    }

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    const HEAD: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\n\
                        property double y\nproperty double z\n";
    const NORMALS: &str = "property double nx\nproperty double ny\nproperty double nz\n";

    #[test]
    fn ply_is_a_mesh_with_faces_and_a_cloud_without() {
        let dir = Scratch::new("ply");
        let face = "element face 1\nproperty list uchar int vertex_indices\n";
        let rows = "0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n";
        // A mesh whose vertices carry normals: still a mesh, the same as `load_mesh` reads.
        let mesh = dir.file(
            "m.ply",
            format!("{HEAD}{NORMALS}{face}end_header\n{rows}3 0 1 2\n").as_bytes(),
        );
        let Input::Mesh(m) = load_input(&mesh).unwrap().input else {
            panic!("a PLY with faces is a mesh")
        };
        assert_eq!(m, crate::io::load_mesh(&mesh).unwrap().mesh);
        // No faces (no face element, or an empty one): a cloud, as `load_point_cloud` reads it.
        for (name, faces) in [
            ("c.ply", ""),
            (
                "e.ply",
                "element face 0\nproperty list uchar int vertex_indices\n",
            ),
        ] {
            let cloud = dir.file(
                name,
                format!("{HEAD}{NORMALS}{faces}end_header\n{rows}").as_bytes(),
            );
            let Input::Cloud(c) = load_input(&cloud).unwrap().input else {
                panic!("{name}: a PLY without faces is a point cloud")
            };
            let want = crate::io::cloud::load_point_cloud(&cloud).unwrap();
            assert_eq!(c.positions(), want.positions());
            assert_eq!(c.normals(), want.normals());
        }
        // No faces and no normals: the cloud reader's error.
        let bare = dir.file(
            "b.ply",
            format!("{HEAD}end_header\n0 0 0\n1 0 0\n0 1 0\n").as_bytes(),
        );
        let err = load_input(&bare).unwrap_err().to_string();
        assert!(err.contains("no scalar property `nx`"), "{err}");
        // Without an extension, a PLY is recognised by its content.
        let plain = dir.file(
            "noext",
            format!("{HEAD}{NORMALS}end_header\n{rows}").as_bytes(),
        );
        assert_eq!(load_input(&plain).unwrap().input.kind(), InputKind::Cloud);
    }

    #[test]
    fn text_clouds_and_other_meshes() {
        let dir = Scratch::new("text");
        let xyz = dir.file("p.xyz", b"0 0 0 0 0 1\n1 0 0 0 0 1\n");
        assert_eq!(load_input(&xyz).unwrap().input.kind(), InputKind::Cloud);
        let off = dir.file("t.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
        assert_eq!(load_input(&off).unwrap().input.kind(), InputKind::Mesh);
        let missing = dir.0.join("missing.obj");
        assert!(matches!(load_input(&missing), Err(InputError::Load(_))));
        #[cfg(feature = "patch")]
        {
            let bad_patch = dir.file("bad.bpt", b"not a patch file");
            assert!(matches!(load_input(&bad_patch), Err(InputError::Patch(_))));
        }
    }
}
