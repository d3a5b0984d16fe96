//! Tests of the plausibility gate.
