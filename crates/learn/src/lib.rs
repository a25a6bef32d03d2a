//! learn (under construction)
