//! Scene building: graphics state to a plain scene description.
