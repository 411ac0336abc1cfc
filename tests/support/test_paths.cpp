// The two absolute paths the tests need, compiled into this file only (CMakeLists.txt): every
// other test file then compiles to the same object in every checkout, so a compiler cache can
// reuse it (.ci/run's sanitizer build).
#include "support/render_util.h"

namespace bdptref::test {

const char* sourceDir() { return BDPTREF_SOURCE_DIR; }
const char* bdptrefBinary() { return BDPTREF_BINARY; }

}  // namespace bdptref::test
