//! Point clouds and the geometry toolkit the pipelines stand on.
//!
//! [`PointCloud`] holds the positions of a scan and any per-point attributes
//! read with it (normals, colours, labels, parameters...) as named `f64`
//! columns, and answers neighbour queries over the library's KD-tree
//! ([`crate::spatial::KdTree`], built once on first use and shared by all
//! queries).
//!
//! * [`neighbours`]: k-nearest and radius queries, one at a time or in
//!   parallel batches.
//! * [`normals`]: PCA normals over k neighbours, oriented towards a viewpoint
//!   or over a minimum spanning tree (Hoppe et al. 1992).
//! * [`hull`]: 3D convex hull (quickhull on exact orientation predicates).
//! * [`hpr`]: hidden point removal, the points visible from a viewpoint
//!   ([Katz07]).
//! * [`boundary`]: boundary loops of a sheet-like patch from the alpha shape
//!   of its projection on the best-fit plane.
//! * [`clean`]: statistical outliers, small fragments, crops and voxel
//!   thinning (which points to keep).
//! * [`corners`]: corners of a closed boundary loop (smallest turning angle or
//!   largest three-point curvature) and the loop's split into sides.
//! * [`segment`]: regions bounded by sharp edges, by octree cells subdivided
//!   where the normals vary ([COONS19]).

pub mod boundary;
pub mod clean;
pub mod corners;
pub(crate) mod forest;
pub mod hpr;
mod hpr_filter;
pub mod hull;
pub mod neighbours;
pub mod normals;
pub mod segment;
#[cfg(test)]
pub(crate) mod testutil;

use std::sync::OnceLock;

use crate::spatial::KdTree;

use crate::{validate_points, Error, Point3, Result, Vector3};

/// The attribute names of normals the readers meet.
const NORMAL_NAMES: [[&str; 3]; 2] = [["nx", "ny", "nz"], ["normal_x", "normal_y", "normal_z"]];

/// A named per-point attribute column.
#[derive(Debug, Clone, PartialEq)]
pub struct Attribute {
    /// Name as in the file (`nx`, `red`, `label`, `u`, ...).
    pub name: String,
    /// One value per point.
    pub values: Vec<f64>,
}

/// A point cloud: positions, named per-point attributes and a lazily built
/// KD-tree for neighbour queries.
///
/// Positions are validated on construction (finite, magnitude below
/// 1e150), so every algorithm over a cloud can
/// rely on them.
#[derive(Debug, Default)]
pub struct PointCloud {
    points: Vec<Point3>,
    attributes: Vec<Attribute>,
    tree: OnceLock<KdTree>,
}

impl Clone for PointCloud {
    fn clone(&self) -> Self {
        Self {
            points: self.points.clone(),
            attributes: self.attributes.clone(),
            tree: OnceLock::new(),
        }
    }
}

impl PartialEq for PointCloud {
    fn eq(&self, other: &Self) -> bool {
        self.points == other.points && self.attributes == other.attributes
    }
}

impl PointCloud {
    /// A cloud of `points` without attributes. Errors name the first point
    /// with a non-finite or out-of-range coordinate.
    pub fn new(points: Vec<Point3>) -> Result<Self> {
        validate_points(&points)?;
        Ok(Self {
            points,
            attributes: Vec::new(),
            tree: OnceLock::new(),
        })
    }

    /// Adds (or replaces) the attribute `name`; it needs one value per point.
    pub fn with_attribute(mut self, name: &str, values: Vec<f64>) -> Result<Self> {
        self.set_attribute(name, values)?;
        Ok(self)
    }

    /// Sets (adds or replaces) the attribute `name`; it needs one value per point.
    pub fn set_attribute(&mut self, name: &str, values: Vec<f64>) -> Result<()> {
        if values.len() != self.points.len() {
            return Err(Error::InvalidInput(format!(
                "attribute '{name}' has {} values for {} points; give one value per point",
                values.len(),
                self.points.len()
            )));
        }
        // exact name first, then a case-insensitive match (the one
        // `attribute` would return), so reading and writing agree
        let at = self
            .attributes
            .iter()
            .position(|a| a.name == name)
            .or_else(|| {
                self.attributes
                    .iter()
                    .position(|a| a.name.eq_ignore_ascii_case(name))
            });
        match at {
            Some(i) => self.attributes[i].values = values,
            None => self.attributes.push(Attribute {
                name: name.to_string(),
                values,
            }),
        }
        Ok(())
    }

    /// The positions.
    pub fn points(&self) -> &[Point3] {
        &self.points
    }

    /// Whether the KD-tree of the neighbour queries is built already (by
    /// an earlier query): a caller with a cheaper way to answer a few
    /// queries uses the tree only when it costs nothing more.
    pub fn has_tree(&self) -> bool {
        self.tree.get().is_some()
    }

    /// Frees the KD-tree of the neighbour queries (about 37 bytes per
    /// point), which the next query builds again: for a caller about to
    /// allocate much while the tree would sit idle.
    ///
    /// ```
    /// use scanfit::{Point3, PointCloud};
    /// let mut cloud = PointCloud::new(vec![Point3::origin(), Point3::new(1.0, 0.0, 0.0)])?;
    /// cloud.tree()?;
    /// cloud.release_tree();
    /// assert!(!cloud.has_tree());
    /// # Ok::<(), scanfit::Error>(())
    /// ```
    pub fn release_tree(&mut self) {
        self.tree = OnceLock::new();
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the cloud has no points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// All attributes, in file order.
    pub fn attributes(&self) -> &[Attribute] {
        &self.attributes
    }

    /// The attribute `name` (exact match first, then ASCII case-insensitive).
    pub fn attribute(&self, name: &str) -> Option<&[f64]> {
        self.attributes
            .iter()
            .find(|a| a.name == name)
            .or_else(|| {
                self.attributes
                    .iter()
                    .find(|a| a.name.eq_ignore_ascii_case(name))
            })
            .map(|a| a.values.as_slice())
    }

    /// Removes the attribute `name`, returning its values.
    pub fn remove_attribute(&mut self, name: &str) -> Option<Vec<f64>> {
        let i = self.attributes.iter().position(|a| a.name == name)?;
        Some(self.attributes.remove(i).values)
    }

    /// The names under which the cloud holds normals: `nx, ny, nz` (PLY,
    /// Open3D) or `normal_x, normal_y, normal_z` (PCL's PCD), if all three
    /// exist (any case).
    fn normal_names(&self) -> Option<[&'static str; 3]> {
        NORMAL_NAMES
            .into_iter()
            .find(|names| names.iter().all(|n| self.attribute(n).is_some()))
    }

    /// Per-point normals from the `nx, ny, nz` (or PCL's `normal_x,
    /// normal_y, normal_z`) attributes, if all three exist.
    pub fn normals(&self) -> Option<Vec<Vector3>> {
        let [a, b, c] = self.normal_names()?;
        let (x, y, z) = (self.attribute(a)?, self.attribute(b)?, self.attribute(c)?);
        Some(
            x.iter()
                .zip(y)
                .zip(z)
                .map(|((&x, &y), &z)| Vector3::new(x, y, z))
                .collect(),
        )
    }

    /// Stores `normals` as the cloud's normal attributes (replacing those it
    /// has under either naming, else as `nx`, `ny`, `nz`).
    pub fn set_normals(&mut self, normals: &[Vector3]) -> Result<()> {
        let names = self.normal_names().unwrap_or(NORMAL_NAMES[0]);
        for (c, name) in names.into_iter().enumerate() {
            self.set_attribute(name, normals.iter().map(|n| n[c]).collect())?;
        }
        Ok(())
    }

    /// The sub-cloud of the points at `indices` (in that order), with their
    /// attributes. Errors on an index out of range.
    pub fn select(&self, indices: &[usize]) -> Result<PointCloud> {
        if let Some(&bad) = indices.iter().find(|&&i| i >= self.points.len()) {
            return Err(Error::InvalidInput(format!(
                "point index {bad} is out of range for a cloud of {} points",
                self.points.len()
            )));
        }
        Ok(PointCloud {
            points: indices.iter().map(|&i| self.points[i]).collect(),
            attributes: self
                .attributes
                .iter()
                .map(|a| Attribute {
                    name: a.name.clone(),
                    values: indices.iter().map(|&i| a.values[i]).collect(),
                })
                .collect(),
            tree: OnceLock::new(),
        })
    }

    /// Axis-aligned bounding box `(min, max)`; `None` for an empty cloud.
    pub fn bounding_box(&self) -> Option<(Point3, Point3)> {
        let first = *self.points.first()?;
        Some(
            self.points
                .iter()
                .fold((first, first), |(lo, hi), p| (lo.inf(p), hi.sup(p))),
        )
    }

    /// Length of the bounding-box diagonal (0 for an empty cloud).
    pub fn diagonal(&self) -> f64 {
        self.bounding_box().map_or(0.0, |(lo, hi)| (hi - lo).norm())
    }

    /// Takes the positions and attributes out of the cloud.
    pub fn into_parts(self) -> (Vec<Point3>, Vec<Attribute>) {
        (self.points, self.attributes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attributes_and_normals_under_either_naming() {
        let p = vec![Point3::origin(), Point3::new(1.0, 0.0, 0.0)];
        let mut c = PointCloud::new(p)
            .unwrap()
            .with_attribute("Normal_X", vec![0.0, 0.0])
            .unwrap()
            .with_attribute("normal_y", vec![0.0, 1.0])
            .unwrap()
            .with_attribute("normal_z", vec![1.0, 0.0])
            .unwrap();
        assert_eq!(c.normals().unwrap()[1], Vector3::y());
        c.set_normals(&[Vector3::x(), Vector3::z()]).unwrap();
        // replaced in place, no second set
        assert_eq!(c.attributes().len(), 3);
        assert_eq!(c.attributes()[0].name, "Normal_X");
        assert_eq!(c.normals().unwrap(), vec![Vector3::x(), Vector3::z()]);
        assert!(c.set_attribute("u", vec![1.0]).is_err());
        let s = c.select(&[1, 1, 0]).unwrap();
        assert_eq!(s.points()[0], Point3::new(1.0, 0.0, 0.0));
        assert_eq!(s.attribute("normal_z"), Some(&[1.0, 1.0, 0.0][..]));
        assert!(c.select(&[2]).is_err());
    }
}
