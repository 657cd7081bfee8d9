// Moved to the reporting layer: fvp/host/report/session_report.h (fvp_host_report). This
// forwarding header stays only while trials/src/trial.cpp, being rewritten elsewhere, still
// includes the old path; it builds nothing into fvp_host_session. Include the new path.
#pragma once

#include "fvp/host/report/session_report.h"
