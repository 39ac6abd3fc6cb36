#include "spherekit/status.h"

namespace spherekit {

const char* error_code_name(ErrorCode code) {
  switch (code) {
#define SPHEREKIT_X(name, exit_code, text) \
  case ErrorCode::name:                    \
    return #name;
    SPHEREKIT_ERROR_CODES(SPHEREKIT_X)
#undef SPHEREKIT_X
  }
  return "Unknown";
}

int error_code_exit_code(ErrorCode code) {
  switch (code) {
#define SPHEREKIT_X(name, exit_code, text) \
  case ErrorCode::name:                    \
    return exit_code;
    SPHEREKIT_ERROR_CODES(SPHEREKIT_X)
#undef SPHEREKIT_X
  }
  return 1;
}

}  // namespace spherekit
