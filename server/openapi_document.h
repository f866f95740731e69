// The API contract, proto/openapi.json, embedded at build time (cmake/EmbedText.cmake).
#pragma once

namespace solidtex::server {
const char* openapi_document();
}
