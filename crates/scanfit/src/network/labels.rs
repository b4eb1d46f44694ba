//! Patch labels from a per-point cloud attribute (issue 15, item 1).
//!
//! A segmented scan carries an integer patch id per point, as CloudCompare
//! and other segmentation tools write it (`label`, `segment`, `scalar_label`,
//! ...). Points with a negative id, or an id on the ignore list, belong to no
//! patch and are left out of the reconstruction.

use crate::{Error, PointCloud, Result};

/// The attribute names tried, in order, when no name is given (matched
/// ASCII case-insensitively).
pub const LABEL_NAMES: [&str; 5] = ["label", "segment", "segment_id", "class", "scalar_label"];

/// Settings of [`read_labels`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LabelConfig {
    /// The attribute holding the patch ids; `None` (default): the first of
    /// [`LABEL_NAMES`] the cloud has.
    pub attribute: Option<String>,
    /// Ids left out besides the negative ones (default none).
    pub ignore: Vec<i64>,
}

/// The patches of a labelled cloud.
#[derive(Debug, Clone, PartialEq)]
pub struct Labels {
    /// The attribute the ids were read from (as named in the cloud).
    pub attribute: String,
    /// The patch ids, ascending; patch `k` of the network has id `ids[k]`.
    pub ids: Vec<i64>,
    /// The cloud's point indices of each patch, ascending.
    pub members: Vec<Vec<usize>>,
    /// Points left out (negative or ignored ids).
    pub ignored: usize,
}

/// Reads the patch id of every point of `cloud` (see the module docs).
///
/// Errors name what to change: no label attribute (the attributes the
/// cloud has are listed), a value that is not an integer (its point index),
/// no patch left after the ignore list.
///
/// ```
/// use scanfit::network::{read_labels, LabelConfig};
/// use scanfit::{Point3, PointCloud};
/// let pts = vec![Point3::new(0., 0., 0.), Point3::new(1., 0., 0.), Point3::new(2., 0., 0.)];
/// let cloud = PointCloud::new(pts)?.with_attribute("Label", vec![3.0, -1.0, 7.0])?;
/// let labels = read_labels(&cloud, &LabelConfig::default())?;
/// assert_eq!(labels.ids, vec![3, 7]);
/// assert_eq!(labels.members, vec![vec![0], vec![2]]);
/// assert_eq!(labels.ignored, 1);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn read_labels(cloud: &PointCloud, cfg: &LabelConfig) -> Result<Labels> {
    let names: Vec<&str> = cloud.attributes().iter().map(|a| a.name.as_str()).collect();
    let found = match &cfg.attribute {
        Some(name) => cloud
            .attributes()
            .iter()
            .find(|a| a.name == *name)
            .or_else(|| {
                cloud
                    .attributes()
                    .iter()
                    .find(|a| a.name.eq_ignore_ascii_case(name))
            })
            .ok_or_else(|| {
                Error::InvalidInput(format!(
                    "the cloud has no attribute '{name}' to read patch labels from; it has {}; pass one of those with --labels",
                    list(&names)
                ))
            })?,
        None => LABEL_NAMES
            .iter()
            .find_map(|n| {
                cloud
                    .attributes()
                    .iter()
                    .find(|a| a.name.eq_ignore_ascii_case(n))
            })
            .ok_or_else(|| {
                Error::InvalidInput(format!(
                    "the cloud has no patch label attribute (looked for {}); it has {}; give each point an integer patch id, or name the attribute with --labels",
                    LABEL_NAMES.join(", "),
                    list(&names)
                ))
            })?,
    };
    let mut ids: Vec<i64> = Vec::new();
    let mut of_point: Vec<Option<i64>> = Vec::with_capacity(found.values.len());
    for (i, &x) in found.values.iter().enumerate() {
        // 2^53: every integer below is exact in f64
        if !x.is_finite() || x.fract() != 0.0 || x.abs() > 9.007_199_254_740_992e15 {
            return Err(Error::InvalidInput(format!(
                "point {i} has patch label {x} in attribute '{}'; labels must be integers (a patch id per point); convert the labels to integers or choose another attribute with --labels",
                found.name
            )));
        }
        let id = x as i64;
        if id < 0 || cfg.ignore.contains(&id) {
            of_point.push(None);
        } else {
            of_point.push(Some(id));
            ids.push(id);
        }
    }
    ids.sort_unstable();
    ids.dedup();
    if ids.is_empty() {
        return Err(Error::InvalidInput(format!(
            "no point of the {} keeps a patch label in attribute '{}' (negative and ignored ids are left out); label the patches with non-negative integers",
            found.values.len(),
            found.name
        )));
    }
    let mut members = vec![Vec::new(); ids.len()];
    let mut ignored = 0;
    for (i, id) in of_point.iter().enumerate() {
        match id.and_then(|id| ids.binary_search(&id).ok()) {
            Some(k) => members[k].push(i),
            None => ignored += 1,
        }
    }
    Ok(Labels {
        attribute: found.name.clone(),
        ids,
        members,
        ignored,
    })
}

fn list(names: &[&str]) -> String {
    if names.is_empty() {
        "no attributes".into()
    } else {
        format!("attributes {}", names.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Point3;

    fn cloud(name: &str, values: Vec<f64>) -> PointCloud {
        let pts = (0..values.len())
            .map(|i| Point3::new(i as f64, 0.0, 0.0))
            .collect();
        PointCloud::new(pts)
            .unwrap()
            .with_attribute(name, values)
            .unwrap()
    }

    #[test]
    fn default_names_in_order_case_insensitive() {
        let c = cloud("Segment_ID", vec![2.0, 2.0, 5.0, 2.0])
            .with_attribute("intensity", vec![1.0; 4])
            .unwrap();
        let l = read_labels(&c, &LabelConfig::default()).unwrap();
        assert_eq!(l.attribute, "Segment_ID");
        assert_eq!(l.ids, vec![2, 5]);
        assert_eq!(l.members, vec![vec![0, 1, 3], vec![2]]);
    }

    #[test]
    fn ignore_list_and_negative() {
        let c = cloud("class", vec![0.0, 1.0, -3.0, 2.0, 1.0]);
        let l = read_labels(
            &c,
            &LabelConfig {
                attribute: None,
                ignore: vec![1],
            },
        )
        .unwrap();
        assert_eq!(l.ids, vec![0, 2]);
        assert_eq!(l.ignored, 3);
    }

    #[test]
    fn float_labels_are_an_error_naming_the_point() {
        let c = cloud("label", vec![1.0, 1.5, 2.0]);
        let e = read_labels(&c, &LabelConfig::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("point 1") && e.contains("1.5") && e.contains("integers"),
            "{e}"
        );
    }

    #[test]
    fn missing_attribute_lists_what_there_is() {
        let c = cloud("intensity", vec![1.0, 2.0]);
        let e = read_labels(&c, &LabelConfig::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("intensity") && e.contains("--labels"), "{e}");
        let e = read_labels(
            &c,
            &LabelConfig {
                attribute: Some("part".into()),
                ignore: vec![],
            },
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("'part'"), "{e}");
    }

    #[test]
    fn everything_ignored_is_an_error() {
        let c = cloud("label", vec![-1.0, -1.0]);
        assert!(read_labels(&c, &LabelConfig::default()).is_err());
    }
}
