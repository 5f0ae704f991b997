//! Empty: this package only brings the `tinybvh-rs` crate (and the tinybvh header it ships) into
//! the registry cache for build.sh.
