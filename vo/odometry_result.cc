#include "vo/odometry_result.h"

namespace vo {

const char* ToString(PredictionSource source) {
  switch (source) {
    case PredictionSource::kNone:
      return "none";
    case PredictionSource::kMotionPrior:
      return "motion_prior";
    case PredictionSource::kImageShift:
      return "image_shift";
    case PredictionSource::kGuided:
      return "guided";
    case PredictionSource::kLastMotion:
      return "last_motion";
  }
  return "unknown";
}

const char* ToString(TrackingStatus status) {
  switch (status) {
    case TrackingStatus::kInitializing:
      return "initializing";
    case TrackingStatus::kTracking:
      return "tracking";
    case TrackingStatus::kLost:
      return "lost";
    case TrackingStatus::kRecovered:
      return "recovered";
  }
  return "unknown";
}

}  // namespace vo
