//! Quality measures of fitted curves.
