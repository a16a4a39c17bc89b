//! `gwn slice`: a PNG picture of the winding number on an axis-aligned plane. Also what `gwn`
//! runs without a subcommand (on the bundled lion head).

use std::path::{Path, PathBuf};

use clap::{Args as ClapArgs, ValueEnum};
use gwn::BoundingBox;
use gwn::input::{Input, InputKind};
use gwn::products::png::Slice;
use gwn::spec::Method;

use crate::common::{CliError, outln, progress};
use crate::method::{MethodArgs, ToleranceArgs, need_mesh};

/// The bundled example mesh (`data/lion-head.off`, CGAL demo data, CC0-1.0): an open lion head
/// with holes, so the slice shows fractional winding numbers.
const LION_HEAD: &[u8] = include_bytes!("../../data/lion-head.off");

/// A coordinate axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Axis {
    /// x
    X,
    /// y
    Y,
    /// z
    Z,
}

impl Axis {
    /// Index 0, 1, 2.
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }
}

/// Render a slice of the winding number as a PNG.
///
/// The picture uses a blue–white–red map centred at w = 0.5 (blue 0 = outside, red 1 = inside;
/// teal towards w = −1, yellow towards w = 2) and has a colour bar with ticks at −1, 0, 0.5, 1, 2
/// below the slice. Image axes: x-slice (y right, z up), y-slice (x right, z up), z-slice
/// (x right, y up).
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Mesh file (OBJ, STL, OFF, PLY, glTF/GLB), patch set (.bpt, .rbpt) or oriented point cloud
    /// (.xyz, .csv, .pts, .ply).
    pub mesh: PathBuf,
    #[command(flatten)]
    pub method: MethodArgs,
    /// Normal axis of the slice plane.
    #[arg(long, value_enum, default_value_t = Axis::Z)]
    pub axis: Axis,
    /// Plane position as a fraction of the mesh's bounding box along --axis (0 = min, 1 = max).
    #[arg(long, default_value_t = 0.5, conflicts_with = "at_coord")]
    pub at: f64,
    /// Plane position as an absolute coordinate (instead of --at).
    #[arg(long, allow_negative_numbers = true)]
    pub at_coord: Option<f64>,
    /// Pixels along the longer side of the slice.
    #[arg(long, default_value_t = 1024)]
    pub res: usize,
    /// Margin around the mesh's bounding box, as a fraction of its largest extent.
    #[arg(long, default_value_t = 0.1)]
    pub margin: f64,
    /// Draw the mesh's cross-section (triangle/plane intersections) in black.
    #[arg(long)]
    pub outline: bool,
    /// Output PNG.
    #[arg(long, short, default_value = "slice.png")]
    pub out: PathBuf,
    #[command(flatten)]
    pub weld: crate::common::WeldArgs,
    #[command(flatten)]
    pub tolerance: ToleranceArgs,
}

/// Runs `gwn slice`.
pub fn run(args: Args) -> Result<(), CliError> {
    args.method.spec(args.tolerance, args.weld).validate()?;
    let input = crate::method::load_input(&args.mesh, args.weld)?;
    render(&input, &args)
}

/// `gwn` without a subcommand: slice the bundled lion head to `slice.png`.
pub fn run_default() -> Result<(), CliError> {
    let loaded =
        gwn::io::load_mesh_from_bytes(LION_HEAD, "data/lion-head.off", Some(gwn::io::Format::Off))?;
    let args = Args {
        mesh: PathBuf::from("data/lion-head.off"),
        method: MethodArgs::default(),
        axis: Axis::X,
        at: 0.5,
        at_coord: None,
        res: 1024,
        margin: 0.1,
        outline: true,
        out: PathBuf::from("slice.png"),
        weld: Default::default(),
        tolerance: ToleranceArgs::default(),
    };
    eprintln!(
        "gwn: no subcommand given; rendering the bundled lion head (an open mesh with holes) \
         like `gwn slice data/lion-head.off --axis x --at 0.5 --outline` (see `gwn --help`)"
    );
    render(&Input::Mesh(loaded.mesh), &args)
}

fn render(input: &Input, args: &Args) -> Result<(), CliError> {
    if args.res == 0 || args.res > 1 << 15 {
        return Err(CliError::msg(format!(
            "--res {} must be between 1 and 32768",
            args.res
        )));
    }
    if !(args.margin.is_finite() && args.margin >= 0.0) {
        return Err(CliError::msg("--margin must be a non-negative number"));
    }
    let outline = if args.outline {
        Some(need_mesh(input, &args.mesh, "--outline")?)
    } else {
        None
    };
    let Some(bbox) = input.bounding_box() else {
        return Err(CliError::msg(format!(
            "{}: has no triangles or points",
            args.mesh.display()
        )));
    };
    let axis = args.axis.index();
    let coord = match args.at_coord {
        Some(c) if c.is_finite() => c,
        Some(_) => return Err(CliError::msg("--at-coord must be finite")),
        None if args.at.is_finite() => bbox.min[axis] + args.at * (bbox.max[axis] - bbox.min[axis]),
        None => return Err(CliError::msg("--at must be finite")),
    };
    let region: BoundingBox = bbox.enlarged(args.margin);
    let slice = Slice::new(&region, axis, coord, args.res);
    let mut spec = args.method.spec(args.tolerance, args.weld);
    // A ray in the plane: one ray serves a whole image column or row (the exact method on
    // meshes and patch sets; the STEP evaluator picks its own rays).
    let method = crate::method::check(&spec, input.kind(), &args.mesh)?;
    if method == Method::Exact && input.kind() != InputKind::Step {
        spec.ray = Some(slice.ray());
    }
    let wn = crate::method::build(&spec, input, &args.mesh)?;
    let pb = progress(
        slice.grid().column_count(gwn::grid::column_axis(&wn)) as u64,
        "slice",
    );
    let values = slice.evaluate_with_progress(&wn, |n| pb.inc(n as u64));
    pb.finish_and_clear();
    let img = slice.render(&values, outline);
    img.save_png(&args.out)
        .map_err(|e| CliError::msg(format!("{}: cannot write: {e}", args.out.display())))?;
    let shown = absolute(&args.out);
    let axis_name = ["x", "y", "z"][axis];
    outln!(
        "wrote {} ({}×{} slice at {axis_name} = {coord}, w in [{:.3}, {:.3}])",
        shown.display(),
        slice.width,
        slice.height,
        values.iter().copied().fold(f64::INFINITY, f64::min),
        values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    )?;
    Ok(())
}

fn absolute(p: &Path) -> PathBuf {
    std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf())
}
