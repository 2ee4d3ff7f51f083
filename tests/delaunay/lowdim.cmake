# 1D/2D Delaunay kernels (core/delaunay/delaunay1*, delaunay2*).
svrc_add_test_suite(NAME svrc_delaunay_lowdim_tests
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/delaunay1_test.cc ${CMAKE_CURRENT_LIST_DIR}/delaunay2_test.cc
  LIBS svrc_delaunay_lowdim svrc_geometry svrc_util
  LABELS core)
