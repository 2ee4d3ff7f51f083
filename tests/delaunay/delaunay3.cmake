# Tests of the 3D Delaunay kernel and point-set tetrahedralization (issue #2).
#   svrc_delaunay3_tests      kernel + point sets (label core: runs under ASan)
#   svrc_point_set_api_tests  core::MeshPlc on point sets (links svrc_core)
#   svrc_delaunay3_cgal_tests tets equal CGAL's Delaunay_triangulation_3 on 10^5
#                             points (CGAL header-only, tests only; label slow)
svrc_add_test_suite(NAME svrc_delaunay3_tests
  SOURCES delaunay3_test.cc delaunay3_queries_test.cc point_set_test.cc
  LIBS svrc_delaunay3 svrc_test_support
  LABELS core
  TIMEOUT 300)

if(EXISTS "${CMAKE_CURRENT_SOURCE_DIR}/point_set_api_test.cc")
  svrc_add_test_suite(NAME svrc_point_set_api_tests
    SOURCES point_set_api_test.cc
    LIBS svrc_core svrc_test_support
    LABELS core
    TIMEOUT 120)
endif()

find_package(CGAL CONFIG QUIET)
if(CGAL_FOUND)
  svrc_add_test_suite(NAME svrc_delaunay3_cgal_tests
    SOURCES cgal_compare_test.cc
    LIBS svrc_delaunay3 CGAL::CGAL
    LABELS slow
    TIMEOUT 600)
else()
  message(STATUS "CGAL not found: svrc_delaunay3_cgal_tests not built")
endif()
