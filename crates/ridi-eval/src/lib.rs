//! Trajectory evaluation for pedestrian inertial navigation.
