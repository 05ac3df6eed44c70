// The version of the code that made a step's outputs (pipeline/step_record.h): the SHA-256 of the
// sources every step of rsibr process is built from (the folders rsibr_pipeline links: core/,
// hdr/, calib/, capture/, bake/, runtime/, compare/, lights/, plan/, pipeline/), computed at build
// time by pipeline/code_version.cmake. A record made by other code is redone, never reused, so no
// one bumps a counter by hand.
#pragma once

namespace rsibr {

// 64 lower-case hex digits.
const char* rsibr_code_version();

}  // namespace rsibr
