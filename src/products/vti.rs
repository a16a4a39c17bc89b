//! VTK ImageData (`.vti`, XML, ascii) for ParaView.
//!
//! A [`GridSpec`] is written as an `ImageData` whose *points* are the grid's cell-centre samples:
//! `Origin` is the first sample `bounds.min + h/2`, `Spacing` is the cell size `h`, and
//! `WholeExtent` is `0 W−1 0 H−1 0 D−1`. The values are one `PointData` array (x fastest, the
//! same order as [`crate::grid`]).

use std::io::{self, Write};
use std::path::Path;

use crate::grid::GridSpec;

/// Writes `values` (one per grid sample, grid order) as an ascii `.vti` with a point array
/// called `name`; `f32` narrows the values to `Float32`.
pub fn write(
    mut w: impl Write,
    spec: &GridSpec,
    name: &str,
    values: &[f64],
    f32_values: bool,
) -> io::Result<()> {
    if values.len() != spec.len() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} values for a grid of {}", values.len(), spec.len()),
        ));
    }
    let [nx, ny, nz] = spec.dims;
    let h = spec.spacing();
    let o = spec.point(0, 0, 0);
    let extent = format!("0 {} 0 {} 0 {}", nx - 1, ny - 1, nz - 1);
    writeln!(w, "<?xml version=\"1.0\"?>")?;
    writeln!(
        w,
        "<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\">"
    )?;
    writeln!(
        w,
        "  <ImageData WholeExtent=\"{extent}\" Origin=\"{:?} {:?} {:?}\" Spacing=\"{:?} {:?} {:?}\">",
        o[0], o[1], o[2], h[0], h[1], h[2]
    )?;
    writeln!(w, "    <Piece Extent=\"{extent}\">")?;
    writeln!(w, "      <PointData Scalars=\"{name}\">")?;
    let ty = if f32_values { "Float32" } else { "Float64" };
    writeln!(
        w,
        "        <DataArray type=\"{ty}\" Name=\"{name}\" format=\"ascii\">"
    )?;
    for row in values.chunks(nx.max(1)) {
        let mut line = String::with_capacity(row.len() * 12);
        for (i, &v) in row.iter().enumerate() {
            if i > 0 {
                line.push(' ');
            }
            if f32_values {
                line.push_str(&format!("{:?}", v as f32));
            } else {
                line.push_str(&format!("{v:?}"));
            }
        }
        writeln!(w, "          {line}")?;
    }
    writeln!(w, "        </DataArray>")?;
    writeln!(w, "      </PointData>")?;
    writeln!(w, "      <CellData>\n      </CellData>")?;
    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </ImageData>")?;
    writeln!(w, "</VTKFile>")?;
    w.flush()
}

/// [`write()`] to a new file at `path`.
pub fn save(
    path: impl AsRef<Path>,
    spec: &GridSpec,
    name: &str,
    values: &[f64],
    f32_values: bool,
) -> io::Result<()> {
    let f = io::BufWriter::new(std::fs::File::create(path)?);
    write(f, spec, name, values, f32_values)
}
