// polydyn (internal) — short reasons for a refused geometry, written into a caller's buffer.
#pragma once

// Formats a reason into why[whySize] (nothing when why is NULL or whySize <= 0).
void pd_why(char* why, int whySize, const char* fmt, ...) __attribute__((format(printf, 3, 4)));
