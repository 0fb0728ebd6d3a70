// Penumbra SDK version. A plugin records the version it was compiled against in its entry point; the
// loader refuses a plugin whose SDK version differs from the runtime's (the ABI of every header in
// this folder may change between SDK versions).
#pragma once

#ifndef PENUMBRA_SDK_VERSION
#define PENUMBRA_SDK_VERSION 1
#endif

#define PENUMBRA_VERSION_STRING "0.1.0"
