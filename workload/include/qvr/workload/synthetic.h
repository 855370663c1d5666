// Seeded synthetic workloads that stand in for recorded game levels until real ones exist.
// A world of triangle-dense objects on a sphere of directions around the viewer, a head that
// turns and a gaze that fixates and saccades; frame sizes follow the paper's Tables 1 and 3,
// with the motion-dependent swings of Fig. 5 coming from what the fovea happens to look at.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "qvr/workload/workload.h"

namespace qvr {

struct SyntheticSpec {
    std::string name = "synthetic-default";
    HmdProfile profile;
    uint64_t seed = 1;
    int frames = 300;
    int batches = 1000;
    // Triangles in view for one eye when looking straight ahead at an average part of the world.
    double triangles_in_view = 1.0e6;
    int objects = 24;                // dense objects scattered around the viewer
    double object_share = 0.6;       // share of the world's triangles that belong to objects
    double object_radius_deg = 6.0;  // mean angular radius of an object
    // Periphery coding: bits per layer pixel at scale 1 and its growth with scale (b·s^γ);
    // head motion raises it (less temporal prediction) by motion_bits_gain per 100 °/s.
    double bits_per_pixel_full = 0.6;
    double bits_scale_exponent = 0.7;
    double motion_bits_gain = 0.25;
    double depth_bits_per_pixel = 0.5;  // static design's encoded depth
    // Head motion: a smooth yaw sweep with this peak angular speed, plus small pitch and roll.
    double head_peak_speed_deg_s = 60.0;
    // Gaze: fixations of this mean duration, saccades to targets within this radius.
    double fixation_ms = 300.0;
    double saccade_radius_deg = 15.0;
};

SyntheticSpec defaultSyntheticSpec();
// Seven workloads mirroring the paper's Table 3 (Doom3-H/-L, HL2-H/-L, GRID, UT3, Wolf), all
// named "synthetic-…" so nobody mistakes them for the games.
std::vector<SyntheticSpec> paperSyntheticSuite();

WorkloadTrace generateSyntheticWorkload(const SyntheticSpec& spec);

}  // namespace qvr
