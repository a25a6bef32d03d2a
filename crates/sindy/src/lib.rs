//! sindy (under construction)
