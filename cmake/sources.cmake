# Source lists shared by the catkin build (CMakeLists.txt) and the sanitizer and fuzzing
# build (test/sanitized/CMakeLists.txt), so neither can drift from the other. Paths are
# relative to the repository root.

# Core library: no ROS headers. model -> kinematics -> workspace -> regions -> planner,
# regions -> surfaces (boundary meshes), plus io for the file formats. Headers under
# include/ are the library's interface; those beside the sources under src/ are internal
# to it (and to its tests).
set(MOW_CORE_SOURCES
  src/model/pose.cpp
  src/model/interval.cpp
  src/model/chain.cpp
  src/model/pss_chain.cpp
  src/model/rss_chain.cpp
  src/model/chain_types.cpp
  src/model/field_reader.cpp
  src/model/robot_model.cpp
  src/model/robot_file.cpp
  src/model/vector_text.cpp
  src/kinematics/working_mode.cpp
  src/kinematics/inverse_kinematics.cpp
  src/kinematics/jacobian.cpp
  src/kinematics/conditioning.cpp
  src/kinematics/pose_analysis.cpp
  src/kinematics/pose_classifier.cpp
  src/kinematics/measure_certificate.cpp
  src/kinematics/proven_share.cpp
  src/kinematics/mode_determinants.cpp
  src/kinematics/segment_distance.cpp
  src/kinematics/constraints.cpp
  src/kinematics/mode_constraints.cpp
  src/workspace/grid.cpp
  src/workspace/block_layout.cpp
  src/workspace/block_storage.cpp
  src/workspace/block_components.cpp
  src/workspace/thin_layers.cpp
  src/workspace/classification.cpp
  src/regions/regions.cpp
  src/regions/singularities.cpp
  src/regions/transitions.cpp
  src/regions/assembly_modes.cpp
  src/regions/conditioning_summary.cpp
  src/regions/workspace_analysis.cpp
  src/regions/memory_estimate.cpp
  src/regions/analysis_admission.cpp
  src/regions/necks.cpp
  src/regions/pose_query.cpp
  src/regions/orientation_coverage.cpp
  src/surfaces/surface_mesh.cpp
  src/surfaces/vertex_conditioning.cpp
  src/planner/path_planner.cpp
  src/planner/region_search.cpp
  src/planner/planning.cpp
  src/planner/trajectory.cpp
  src/planner/verification.cpp
  src/planner/plan_playback.cpp
  src/planner/path_request.cpp
  src/description/robot_description.cpp
  src/io/pose_csv.cpp
  src/io/text_file.cpp
  src/io/region_label_octree.cpp
  src/io/octree_export.cpp
  src/io/octree_pyramid.cpp
  src/io/mesh_files.cpp
  src/io/checksum.cpp
  src/io/workspace_files.cpp
  src/io/cache_manifest.cpp
  src/io/workspace_cache.cpp
  src/io/workspace_state.cpp
  src/io/plan_csv.cpp
  src/io/workspace_request.cpp
  src/io/display_sampling.cpp
  src/io/entry_computation.cpp
  src/io/workspace_worker.cpp
  src/io/workspace_store.cpp
  src/sweep/study.cpp
  src/sweep/results_file.cpp
  src/sweep/sweep_runner.cpp
)

set(MOW_CLI_SOURCES
  src/cli/mow.cpp
  src/cli/arguments.cpp
  src/cli/analysis_request.cpp
  src/cli/info_command.cpp
  src/cli/eval_command.cpp
  src/cli/workspace_command.cpp
  src/cli/plan_command.cpp
  src/cli/urdf_command.cpp
  src/cli/necks_command.cpp
  src/cli/sweep_command.cpp
)

# mow sweep under mpirun (docs/sweep.md): only where MPI is found, and never in the core.
set(MOW_CLI_MPI_SOURCES
  src/cli/sweep_mpi.cpp
)

# Unit tests of the core library (gtest, no ROS master), each test/<name>.cpp.
set(MOW_CORE_TESTS test_chains test_jacobians test_robots test_robot_file_errors test_pose_csv test_octree_export
                   test_workspace test_engine_reference test_cache test_store test_planner test_planning test_pose_classifier test_a_star
                   test_display_sampling test_measure_sign test_measure_certificate test_margin test_constraints test_pose_query
                   test_sweep test_certified_volumes test_orientation_set test_orientation_plan test_surface_mesh
                   test_conditioning)
