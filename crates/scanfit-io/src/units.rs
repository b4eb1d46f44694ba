//! The length unit a CAD file declares for its coordinates.
//!
//! scanfit never scales the data: the coordinates are written as they are,
//! and the unit says what they mean, so a CAD system that converts to its
//! own unit on import (OpenCASCADE reads everything into millimetres) gets
//! the right size. STEP declares the unit in the representation context
//! (`SI_UNIT` with a prefix for mm, cm and m; a `CONVERSION_BASED_UNIT` on
//! the millimetre for inch and foot, ISO 10303-41); IGES in the global
//! section's unit flag and unit name (parameters 14 and 15, IGES 5.3
//! §2.2.4.3).

use std::fmt;
use std::str::FromStr;

/// A length unit for STEP and IGES files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LengthUnit {
    /// Millimetre (the default).
    #[default]
    Millimetre,
    /// Centimetre.
    Centimetre,
    /// Metre.
    Metre,
    /// Inch (25.4 mm).
    Inch,
    /// Foot (304.8 mm).
    Foot,
}

impl LengthUnit {
    /// Every unit, in the order the command line lists them.
    pub const ALL: [LengthUnit; 5] = [
        LengthUnit::Millimetre,
        LengthUnit::Centimetre,
        LengthUnit::Metre,
        LengthUnit::Inch,
        LengthUnit::Foot,
    ];

    /// The short name (`mm`, `cm`, `m`, `in`, `ft`).
    pub fn symbol(self) -> &'static str {
        match self {
            LengthUnit::Millimetre => "mm",
            LengthUnit::Centimetre => "cm",
            LengthUnit::Metre => "m",
            LengthUnit::Inch => "in",
            LengthUnit::Foot => "ft",
        }
    }

    /// One unit in millimetres.
    ///
    /// ```
    /// use scanfit_io::units::LengthUnit;
    /// assert_eq!(LengthUnit::Foot.millimetres(), 304.8);
    /// assert_eq!("m".parse::<LengthUnit>().unwrap().millimetres(), 1000.0);
    /// ```
    pub fn millimetres(self) -> f64 {
        match self {
            LengthUnit::Millimetre => 1.0,
            LengthUnit::Centimetre => 10.0,
            LengthUnit::Metre => 1000.0,
            LengthUnit::Inch => 25.4,
            LengthUnit::Foot => 304.8,
        }
    }

    /// The IGES unit flag (global parameter 14, IGES 5.3 table 3).
    pub fn iges_flag(self) -> u32 {
        match self {
            LengthUnit::Inch => 1,
            LengthUnit::Millimetre => 2,
            LengthUnit::Foot => 4,
            LengthUnit::Metre => 6,
            LengthUnit::Centimetre => 10,
        }
    }

    /// The IGES unit name (global parameter 15, the names table 3 gives).
    pub fn iges_name(self) -> &'static str {
        match self {
            LengthUnit::Inch => "INCH",
            LengthUnit::Millimetre => "MM",
            LengthUnit::Foot => "FT",
            LengthUnit::Metre => "M",
            LengthUnit::Centimetre => "CM",
        }
    }

    /// The STEP entities declaring this unit, written with `add` (which
    /// returns an entity's id); returns the id of the `LENGTH_UNIT`.
    pub(crate) fn step_entities(self, mut add: impl FnMut(&str) -> usize) -> usize {
        let si = |prefix: &str| format!("(LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT({prefix},.METRE.))");
        match self {
            LengthUnit::Millimetre => add(&si(".MILLI.")),
            LengthUnit::Centimetre => add(&si(".CENTI.")),
            LengthUnit::Metre => add(&si("$")),
            LengthUnit::Inch | LengthUnit::Foot => {
                let mm = add(&si(".MILLI."));
                let dims = add("DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.)");
                let (name, factor) = match self {
                    LengthUnit::Inch => ("INCH", "25.4"),
                    _ => ("FOOT", "304.8"),
                };
                let measure = add(&format!(
                    "LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE({factor}),#{mm})"
                ));
                add(&format!(
                    "(CONVERSION_BASED_UNIT('{name}',#{measure}) LENGTH_UNIT() NAMED_UNIT(#{dims}))"
                ))
            }
        }
    }
}

impl fmt::Display for LengthUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.symbol())
    }
}

impl FromStr for LengthUnit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        LengthUnit::ALL
            .into_iter()
            .find(|u| u.symbol().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("unknown length unit '{s}': use mm, cm, m, in or ft"))
    }
}

/// Options of the CAD writers beyond the geometry.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct CadOptions {
    /// The unit the coordinates are in (default millimetres).
    pub units: LengthUnit,
}

impl CadOptions {
    /// Options with `units`.
    pub fn with_units(units: LengthUnit) -> Self {
        Self { units }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_flags_are_the_standards() {
        for u in LengthUnit::ALL {
            assert_eq!(u.symbol().parse::<LengthUnit>().unwrap(), u);
        }
        // IGES 5.3 table 3
        let flags: Vec<u32> = LengthUnit::ALL.iter().map(|u| u.iges_flag()).collect();
        assert_eq!(flags, [2, 10, 6, 1, 4]);
        assert!("km".parse::<LengthUnit>().is_err());
    }
}
