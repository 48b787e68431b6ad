// Stereo datasets on disk: a writer for the KITTI odometry layout (optionally also EuRoC/ASL or
// a TUM-style stereo layout), and readers for the three layouts, so simulated and real sequences
// run through the same VO. One header per part, all included here:
//
//   dataset/common.h          DatasetFrame (one stereo frame in memory), DatasetFormat, TimeToNs,
//                             AssociateGroundTruth; the shape every reader has
//   dataset/writer.h          DatasetWriter: the KITTI layout, plus EuRoC/ASL or TUM-style
//   dataset/kitti.h           the KITTI odometry layout, ReadKittiCalib, KittiReader
//   dataset/euroc.h           the EuRoC/ASL layout, ReadEurocSensorYaml, EurocReader (raw pairs)
//   dataset/euroc_imu.h       EuRoC's imu0/ written and read, the ground truth at the IMU rate
//   dataset/tum.h             the TUM-style stereo layout, TumReader
//   dataset/rosbag.h          ROS 1 bags as EuRoC's: RosbagWriter, RosbagReader (VOBENCH_ROSBAG)
//   dataset/rectification.h   raw pair -> the ideal rectified pair the VO expects (EuRoC)
//
// (dataset/internal.h holds the helpers these files share; it is not part of this API.)
//
// Errors: functions return false and fill *error with the file (and line) and what was expected.
#pragma once

#include "harness/dataset/common.h"
#include "harness/dataset/euroc.h"
#include "harness/dataset/euroc_imu.h"
#include "harness/dataset/kitti.h"
#include "harness/dataset/rectification.h"
#include "harness/dataset/rig.h"
#include "harness/dataset/rosbag.h"
#include "harness/dataset/tum.h"
#include "harness/dataset/writer.h"
