//! rrt on a host.
