# The Python module needs Python's headers, pybind11 and NumPy (Debian: pybind11-dev,
# python3-pybind11, python3-numpy; ./bd installs them). Without them the rest builds as before,
# and the configure step says what is missing. BD_PYTHON is set when the module is built;
# BD_PYTEST when pytest (python3-pytest) can run its tests.
set(BD_PYTHON OFF)
set(BD_PYTEST OFF)
if(NOT BD_BUILD_PYTHON)
  return()
endif()
# Debian's interpreter, the one its python3-* packages serve, unless told otherwise (a pyenv or
# virtualenv python3 earlier on PATH has no NumPy from apt)
if(NOT DEFINED Python_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python_EXECUTABLE /usr/bin/python3)
endif()
find_package(Python 3.9 COMPONENTS Interpreter Development.Module)
if(Python_FOUND)
  find_package(pybind11 2.6 CONFIG QUIET)
endif()
if(NOT Python_FOUND OR NOT pybind11_FOUND)
  message(STATUS "Python module balance_design not built: needs Python 3 headers and pybind11 "
                 "(Debian: pybind11-dev python3-pybind11)")
  return()
endif()
execute_process(COMMAND ${Python_EXECUTABLE} -c "import numpy" RESULT_VARIABLE numpy_rc
                OUTPUT_QUIET ERROR_QUIET)
if(NOT numpy_rc EQUAL 0)
  message(STATUS "Python module balance_design not built: ${Python_EXECUTABLE} has no NumPy "
                 "(Debian: python3-numpy)")
  return()
endif()
set(BD_PYTHON ON)
execute_process(COMMAND ${Python_EXECUTABLE} -c "import pytest" RESULT_VARIABLE pytest_rc
                OUTPUT_QUIET ERROR_QUIET)
if(pytest_rc EQUAL 0)
  set(BD_PYTEST ON)
else()
  message(STATUS "Python tests not registered: ${Python_EXECUTABLE} has no pytest "
                 "(Debian: python3-pytest)")
endif()
