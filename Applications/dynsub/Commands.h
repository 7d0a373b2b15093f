#pragma once
// The subcommands of `dynsub`: each adds itself to the application and runs
// when selected. Errors are thrown as dynsub::Error and reported by main().
namespace CLI {
class App;
}

namespace dynsub::app {

void addLimitCommand(CLI::App& app);
void addMeshCommand(CLI::App& app);
void addFitCommand(CLI::App& app);
void addDeformCommand(CLI::App& app);
void addSegmentCommand(CLI::App& app);
void addEvaluateCommand(CLI::App& app);
void addSubjectCommand(CLI::App& app);
void addRenderCommand(CLI::App& app);
void addViewCommand(CLI::App& app);
void addSolidCommand(CLI::App& app);

}  // namespace dynsub::app
