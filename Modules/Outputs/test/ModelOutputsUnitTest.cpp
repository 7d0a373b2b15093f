// writeModelOutputs refuses a model the readers would refuse, saying what
// went wrong with the run, and writes nothing for it.
#include "dynsub/ModelOutputs.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "dynsub/Error.h"
#include "dynsub/Report.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/Tessellation.h"

namespace {

// The error writeModelOutputs gives for `mesh`, into a fresh directory that
// must stay empty.
std::string outputError(const dynsub::ControlMesh& mesh) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("dynsub_model_outputs_" + std::to_string(::getpid()) + "_" +
                                     ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::string error;
  try {
    dynsub::writeModelOutputs(dir, mesh, dynsub::TriangleSurface{}, dynsub::Report());
  } catch (const dynsub::Error& e) {
    error = e.what();
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir)) << "a refused model left files in " << dir;
  std::filesystem::remove_all(dir);
  return error;
}

TEST(ModelOutputs, ADivergedModelIsSaidToHaveDivergedAndACollapsedOneToHaveCollapsed) {
  dynsub::ControlMesh diverged = dynsub::makeCube98();
  dynsub::MatrixX3 points = diverged.points();
  points(5, 1) = 1e12;
  diverged.setPoints(points);
  const std::string far = outputError(diverged);
  EXPECT_NE(far.find("the model diverged: control vertex 5"), std::string::npos) << far;

  dynsub::ControlMesh collapsed = dynsub::makeCube98();
  collapsed.setPoints(dynsub::MatrixX3::Zero(collapsed.vertexCount(), 3));
  const std::string flat = outputError(collapsed);
  EXPECT_NE(flat.find("the model collapsed"), std::string::npos) << flat;
}

}  // namespace
