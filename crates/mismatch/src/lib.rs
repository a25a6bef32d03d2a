//! mismatch (under construction)
