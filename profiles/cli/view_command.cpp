// `brickworld view FILE -o PAGE.html`: a recording (`run SCENE --record FILE`) as one
// self-contained page: the scene in three.js with play, pause, step and scrub, bodies coloured
// by state, contacts, OctoBVH boxes by depth, and the frame-time timeline by stage below it.
#include <cstdio>
#include <memory>

#include "cli/command_registry.h"
#include "recording/viewer_page.h"

namespace bw::cli {
namespace {

CommandRegistration reg{"view", "Write a self-contained HTML replay page of a recording made by `run SCENE --record FILE`", [](CLI::App& cmd) {
  auto input = std::make_shared<std::string>();
  auto output = std::make_shared<std::string>();
  auto three = std::make_shared<std::string>(defaultThreeJsDir());
  cmd.add_option("recording", *input, "the recording (.bwr) written by run --record")->required();
  cmd.add_option("-o,--output", *output, "the page to write (.html)")->required();
  cmd.add_option("--three-dir", *three, "where three.min.js and examples/js/controls/OrbitControls.js are (Debian's libjs-three)");
  return [=] {
    const ViewerPageStats st = writeViewerPage(*input, *output, *three);
    std::printf("view: %s -> %s: %u frames, %u bodies, %u grids (%llu bricks at the start; %u grids drawn as OctoBVH boxes), %.1f MB of "
                "recording in a %.1f MB page%s\n",
                input->c_str(), output->c_str(), st.frames, st.bodies, st.grids, (unsigned long long)st.bricks, st.boxGrids,
                st.recordingBytes / 1e6, st.pageBytes / 1e6,
                st.complete ? "" : " (the recording has no END_: the run did not finish; its complete frames are shown)");
    return 0;
  };
}};

}  // namespace
}  // namespace bw::cli
