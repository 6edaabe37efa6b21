#pragma once
// /query_pose between its messages and the core (regions/pose_query.h): translation only,
// every figure comes from the core library.

#include <geometry_msgs/Pose.h>

#include "maximal_workspace/QueryPose.h"
#include "maximal_workspace/regions/pose_query.h"

namespace maximal_workspace {

// The request's pose in ZYZ angles; throws InputError naming it ("pose: position must be
// finite", "pose: orientation must be a unit quaternion").
Pose queryRequestPose(const QueryPose::Request& request, const RobotModel& model);

// Everything of a successful response but success and message.
void fillQueryResponse(const WorkspaceAnalysis& analysis, const PoseQuery& query, QueryPose::Response& response);

geometry_msgs::Pose poseMessage(const Pose& pose);

}  // namespace maximal_workspace
