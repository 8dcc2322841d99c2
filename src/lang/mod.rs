//! Scene language: tokens, directives, parameter lists, Include splicing and diagnostics.
