// ThreadSanitizer suppressions for third-party code only, linked into the camera and vision tests
// that run under TSan (label concurrency; CREASE_TSAN_THIRD_PARTY). Nothing of ours is suppressed.
//   libgdal: OpenCV's imgcodecs registers GDAL's drivers (GDALAllRegister) the first time any
//   image is read or written; GDAL's CPLCreateOrAcquireMutexEx takes its global mutex and the
//   new one in both orders on that one thread, which TSan reports as a lock-order inversion.
#ifdef CREASE_SANITIZER_THREAD
extern "C" const char* __tsan_default_suppressions();
extern "C" const char* __tsan_default_suppressions() { return "deadlock:libgdal.so\n"; }
#endif
