//! SVG line plots.
