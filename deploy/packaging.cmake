# Installation and the Debian packages (cpack -G DEB, see .ci/package).
#
# Two packages, so that a production host installs only the bridge:
#
# dnbridge (component bridge)
#   /usr/bin                      dnbridge, dnbctl
#   /usr/share/man                dnbridge(8), dnbctl(1), dnbridge.toml(5)
#   /usr/share/bash-completion    dnbctl's completion
#   /usr/share/dnbridge/idl       the data model, for supervisory programs
#   /etc/dnbridge                 rack-example.toml and cyclonedds.xml (conffiles)
#   /usr/share/dnbridge/cyclonedds/loopback.xml   DDS on this host only
#   /usr/share/dnbridge/security  make-site-pki.sh: a site's DDS Security PKI
#   /usr/share/dnbridge/networkd  systemd-networkd examples for the CAN interfaces
#   /usr/share/dnbridge/prometheus  a scrape configuration and alert rules
#   /usr/share/dnbridge/eds       example EDS files (deploy/eds)
#   /usr/share/doc/dnbridge       operations.md (deploy/README.md), security.md
#                                 (deploy/security/README.md), data-model.md
#                                 (idl/README.md), copyright, changelog.gz
#   systemd's unit directory      dnbridge@.service (a template: nothing starts
#                                 until an instance is enabled)
#   /usr/lib/sysusers.d           the dedicated user dnbridge
#
# dnbridge-sim (component sim): the simulator, for trying configurations,
# training and demonstrations
#   /usr/bin                      dnbridge-sim, cdn127-sim, dnbridge-demo
#   /usr/share/man                dnbridge-sim(1), cdn127-sim(1), dnbridge-demo(1)
#   /usr/share/dnbridge/cdn127-sim-example.toml   cdn127-sim's device readings
#   /usr/share/doc/dnbridge-sim   copyright, changelog.gz
#
# The programs are built with Debian's hardening flags (DNBRIDGE_HARDENING,
# on in the release preset, which .ci/package builds); the package test
# checks each binary for them.
#
# The example rack configuration is installed under /etc/dnbridge as the
# starting point of a real one: a template unit starts nothing by itself,
# and the package enables no instance, so no bridge runs until an
# administrator enables dnbridge@RACK for a /etc/dnbridge/RACK.toml.
include(GNUInstallDirs)

find_package(PkgConfig REQUIRED)
pkg_get_variable(DNBRIDGE_SYSTEMD_UNIT_DIR systemd systemdsystemunitdir)
pkg_get_variable(DNBRIDGE_SYSUSERS_DIR systemd sysusersdir)
if(NOT DNBRIDGE_SYSTEMD_UNIT_DIR)
  set(DNBRIDGE_SYSTEMD_UNIT_DIR /lib/systemd/system)
endif()
if(NOT DNBRIDGE_SYSUSERS_DIR)
  set(DNBRIDGE_SYSUSERS_DIR /usr/lib/sysusers.d)
endif()

set(DNBRIDGE_PACKAGE_MAINTAINER "dnbridge maintainers <maintainers@dnbridge.example.org>"
    CACHE STRING "The Debian packages' Maintainer field: the site's or integrator's address")

# The changelog's newest entry is the version the packages are built as.
set(changelog ${PROJECT_SOURCE_DIR}/deploy/debian/changelog)
file(STRINGS ${changelog} changelog_top LIMIT_COUNT 1)
if(NOT changelog_top MATCHES "^dnbridge \\(${PROJECT_VERSION}\\) ")
  message(FATAL_ERROR "deploy/debian/changelog starts with '${changelog_top}', "
                      "not an entry for version ${PROJECT_VERSION}")
endif()

# Man pages and the changelog, gzipped as Debian installs them.
set(man_dir ${CMAKE_CURRENT_BINARY_DIR}/man)
set(package_files "")
# dnbridge.toml(5)'s key reference, generated from the rack file's key table.
set(config_keys_roff ${man_dir}/dnbridge.toml.keys)
add_custom_command(
  OUTPUT ${config_keys_roff}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${man_dir}
  COMMAND config_keys_roff ${config_keys_roff}
  DEPENDS config_keys_roff
  COMMENT "dnbridge.toml(5): the key reference")
foreach(page dnbridge.8 dnbctl.1 dnbridge.toml.5 dnbridge-sim.1 cdn127-sim.1 dnbridge-demo.1)
  set(example_args "")
  set(example_deps "")
  if(page STREQUAL "dnbridge.toml.5")
    set(example_args -DEXAMPLE=${PROJECT_SOURCE_DIR}/deploy/config/rack-example.toml
                     -DKEYS=${config_keys_roff})
    set(example_deps ${PROJECT_SOURCE_DIR}/deploy/config/rack-example.toml ${config_keys_roff})
  endif()
  add_custom_command(
    OUTPUT ${man_dir}/${page} ${man_dir}/${page}.gz
    COMMAND ${CMAKE_COMMAND} -E make_directory ${man_dir}
    COMMAND ${CMAKE_COMMAND} -DINPUT=${PROJECT_SOURCE_DIR}/deploy/man/${page}
            -DOUTPUT=${man_dir}/${page} -DVERSION=${PROJECT_VERSION} ${example_args}
            -P ${PROJECT_SOURCE_DIR}/deploy/man/render.cmake
    DEPENDS ${PROJECT_SOURCE_DIR}/deploy/man/${page} ${PROJECT_SOURCE_DIR}/deploy/man/render.cmake
            ${example_deps}
    COMMENT "Man page ${page}")
  list(APPEND package_files ${man_dir}/${page}.gz)
endforeach()
set(changelog_gz ${CMAKE_CURRENT_BINARY_DIR}/changelog.gz)
add_custom_command(
  OUTPUT ${changelog_gz}
  COMMAND gzip -9n < ${changelog} > ${changelog_gz}
  DEPENDS ${changelog}
  COMMENT "deploy/debian/changelog, gzipped")
list(APPEND package_files ${changelog_gz})
add_custom_target(dnbridge_package_files ALL DEPENDS ${package_files})

# dnbridge
install(TARGETS dnbridge dnbctl RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT bridge)
install(FILES ${man_dir}/dnbridge.8.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man8 COMPONENT bridge)
install(FILES ${man_dir}/dnbctl.1.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 COMPONENT bridge)
install(FILES ${man_dir}/dnbridge.toml.5.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man5
        COMPONENT bridge)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/bash-completion/dnbctl
        DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions COMPONENT bridge)
install(FILES ${PROJECT_SOURCE_DIR}/idl/dnbridge.idl
        DESTINATION ${CMAKE_INSTALL_DATADIR}/dnbridge/idl COMPONENT bridge)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/cyclonedds/loopback.xml
        DESTINATION ${CMAKE_INSTALL_DATADIR}/dnbridge/cyclonedds COMPONENT bridge)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/config/rack-example.toml
              ${PROJECT_SOURCE_DIR}/deploy/cyclonedds/cyclonedds.xml
        DESTINATION /etc/dnbridge COMPONENT bridge)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/systemd/dnbridge@.service
        DESTINATION ${DNBRIDGE_SYSTEMD_UNIT_DIR} COMPONENT bridge)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/systemd/dnbridge.sysusers
        DESTINATION ${DNBRIDGE_SYSUSERS_DIR} RENAME dnbridge.conf COMPONENT bridge)
install(PROGRAMS ${PROJECT_SOURCE_DIR}/deploy/security/make-site-pki.sh
        DESTINATION ${CMAKE_INSTALL_DATADIR}/dnbridge/security COMPONENT bridge)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/prometheus/prometheus.yml
              ${PROJECT_SOURCE_DIR}/deploy/prometheus/dnbridge-alerts.yml
        DESTINATION ${CMAKE_INSTALL_DATADIR}/dnbridge/prometheus COMPONENT bridge)
file(GLOB DNBRIDGE_NETWORKD_EXAMPLES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/deploy/networkd/*.network
     ${PROJECT_SOURCE_DIR}/deploy/networkd/*.link)
install(FILES ${DNBRIDGE_NETWORKD_EXAMPLES}
        DESTINATION ${CMAKE_INSTALL_DATADIR}/dnbridge/networkd COMPONENT bridge)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR}
        RENAME operations.md COMPONENT bridge)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/security/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR}
        RENAME security.md COMPONENT bridge)
install(FILES ${PROJECT_SOURCE_DIR}/idl/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR}
        RENAME data-model.md COMPONENT bridge)
file(GLOB DNBRIDGE_EDS_EXAMPLES ${PROJECT_SOURCE_DIR}/deploy/eds/*.eds)
install(FILES ${DNBRIDGE_EDS_EXAMPLES} DESTINATION ${CMAKE_INSTALL_DATADIR}/dnbridge/eds
        COMPONENT bridge)

# dnbridge-sim
install(TARGETS dnbridge-sim cdn127-sim dnbridge-demo RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        COMPONENT sim)
install(FILES ${man_dir}/dnbridge-sim.1.gz ${man_dir}/cdn127-sim.1.gz ${man_dir}/dnbridge-demo.1.gz
        DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 COMPONENT sim)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/config/cdn127-sim-example.toml
        DESTINATION ${CMAKE_INSTALL_DATADIR}/dnbridge COMPONENT sim)

# Each package's copyright and changelog, in its own documentation directory.
set(components bridge sim)
set(packages dnbridge dnbridge-sim)
foreach(component package IN ZIP_LISTS components packages)
  install(FILES ${PROJECT_SOURCE_DIR}/deploy/debian/copyright ${changelog_gz}
          DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/doc/${package} COMPONENT ${component})
endforeach()

set(CPACK_GENERATOR DEB)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL bridge sim)
set(CPACK_PACKAGE_NAME dnbridge)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "${DNBRIDGE_PACKAGE_MAINTAINER}")
set(CPACK_DEBIAN_PACKAGE_SECTION net)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)

set(CPACK_DEBIAN_BRIDGE_PACKAGE_NAME dnbridge)
set(CPACK_COMPONENT_BRIDGE_DESCRIPTION
    "DeviceNet master for equipment racks, bridged to DDS\n\
dnbridge is the DeviceNet master (scanner) of an equipment rack's CAN ports\n\
and publishes the rack's CDN127-fronted pumps as typed DDS topics (Eclipse\n\
Cyclone DDS), taking commands from supervisory programs. The outputs' safe\n\
state is downloaded into every device and checked; a lost master, commander\n\
or node leaves the outputs idle until a fresh command.\n\
.\n\
This package has the bridge, dnbctl (a command-line client), the IDL of the\n\
data model and the systemd template unit dnbridge@.service. The simulator\n\
is in dnbridge-sim.")
# postinst makes the user with systemd-sysusers, or useradd (passwd) without.
set(CPACK_DEBIAN_BRIDGE_PACKAGE_DEPENDS "passwd")
# openssl: make-site-pki.sh, on the host that makes a site's PKI.
set(CPACK_DEBIAN_BRIDGE_PACKAGE_RECOMMENDS "systemd, openssl")
set(CPACK_DEBIAN_BRIDGE_PACKAGE_SUGGESTS "dnbridge-sim, can-utils")
set(CPACK_DEBIAN_BRIDGE_PACKAGE_CONTROL_EXTRA
    "${PROJECT_SOURCE_DIR}/deploy/debian/conffiles;${PROJECT_SOURCE_DIR}/deploy/debian/postinst;${PROJECT_SOURCE_DIR}/deploy/debian/prerm;${PROJECT_SOURCE_DIR}/deploy/debian/postrm")

set(CPACK_DEBIAN_SIM_PACKAGE_NAME dnbridge-sim)
set(CPACK_DEBIAN_SIM_PACKAGE_SECTION misc)
set(CPACK_COMPONENT_SIM_DESCRIPTION
    "simulated CDN127 pump interfaces and racks for dnbridge\n\
The simulator of dnbridge, for trying a rack configuration, training and\n\
demonstrations, never needed on a production host. dnbridge-sim is the\n\
bridge with an in-process simulated bus of CDN127s; cdn127-sim simulates\n\
CDN127s on a SocketCAN interface (vcan or a real bus), each as strict or\n\
lenient as a device in the field; dnbridge-demo shows the master scanning a\n\
simulated rack, live in a terminal.")
# dnbctl, to watch and command a simulated rack.
set(CPACK_DEBIAN_SIM_PACKAGE_RECOMMENDS "dnbridge (= ${PROJECT_VERSION})")

# Library dependencies as dpkg-shlibdeps finds them in the binaries.
find_program(DNBRIDGE_DPKG_SHLIBDEPS dpkg-shlibdeps)
if(NOT DNBRIDGE_DPKG_SHLIBDEPS)
  message(STATUS "dpkg-shlibdeps (package dpkg-dev) not found: packages built here would have no Depends (bash .ci/deps test installs it)")
endif()
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
# Debug information stays in the build tree.
set(CPACK_STRIP_FILES ON)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
include(CPack)
