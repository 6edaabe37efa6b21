#include "pose_query_messages.h"

#include <cmath>

#include <Eigen/Geometry>

#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/planner/path_request.h"
#include "workspace_messages.h"

namespace maximal_workspace {

Pose queryRequestPose(const QueryPose::Request& request, const RobotModel& model) {
  return requestedPose(requestPose(request.pose), model, "pose");
}

geometry_msgs::Pose poseMessage(const Pose& pose) {
  geometry_msgs::Pose message;
  message.position = pointMessage(pose.position);
  const Eigen::Quaterniond q(pose.rotation());
  message.orientation.w = q.w();
  message.orientation.x = q.x();
  message.orientation.y = q.y();
  message.orientation.z = q.z();
  return message;
}

void fillQueryResponse(const WorkspaceAnalysis& analysis, const PoseQuery& query, QueryPose::Response& response) {
  const bool assembled = query.kinematics.ikp.assembled;
  const std::vector<Region>& regions = analysis.regions();
  response.inside = assembled;
  response.on_grid = query.on_grid;
  response.in_workspace = query.in_workspace;
  response.step = analysis.grid().step(0);
  if (query.on_grid) {
    response.cell = query.cell;
    response.cell_centre = poseMessage(analysis.grid().pose(query.cell));
  }
  for (std::size_t m = 0; m < analysis.modes().size(); ++m) {
    PoseWorkingMode mode;
    mode.working_mode = analysis.modes()[m].name;
    mode.det = assembled ? query.kinematics.modes[m].singularity.det : NAN;
    mode.measure = assembled ? query.kinematics.modes[m].singularity.measure : NAN;
    mode.sign = assembled ? bandedSign(mode.measure, 0.0) : 0;
    mode.conditioning = assembled ? query.kinematics.modes[m].conditioning : NAN;
    mode.admissible = assembled && query.kinematics.modes[m].limits.satisfied();
    mode.region = query.regions[m];
    if (mode.region >= 0) {
      mode.region_sign = regions[mode.region].sign;
      mode.region_debris = regions[mode.region].debris;
    }
    response.working_modes.push_back(mode);
  }
  for (const AssemblyModeAtPose& at : query.assembly_modes) {
    PoseAssemblyMode assembly_mode;
    assembly_mode.sign = at.sign;
    assembly_mode.in_maximal = at.in_maximal;
    assembly_mode.reachable = at.reachable;
    for (int m : at.modes) assembly_mode.working_modes.push_back(analysis.modes()[m].name);
    assembly_mode.regions = at.regions;
    assembly_mode.has_nearest = at.has_nearest;
    if (at.has_nearest) assembly_mode.nearest = poseMessage(at.nearest);
    assembly_mode.distance = at.distance;
    assembly_mode.has_coverage = at.has_coverage;
    assembly_mode.coverage = at.coverage;
    assembly_mode.traditional_coverage = at.traditional_coverage;
    response.assembly_modes.push_back(assembly_mode);
  }
}

}  // namespace maximal_workspace
