# Installation and the Debian package (cpack -G DEB, see .ci/package).
#
# What goes where:
#   /usr/bin                      dnbridge, dnbctl, cdn127-sim
#   /usr/share/dnbridge/idl       the data model, for supervisory programs
#   /etc/dnbridge                 rack-example.toml and cyclonedds.xml (conffiles)
#   /usr/share/dnbridge/cyclonedds/loopback.xml   DDS on this host only
#   /usr/share/dnbridge/security  make-site-pki.sh: a site's DDS Security PKI
#   /usr/share/dnbridge/networkd  systemd-networkd examples for the CAN interfaces
#   /usr/share/dnbridge/cdn127-sim-example.toml   cdn127-sim's device readings
#   /usr/share/doc/dnbridge       README.md; operations.md (deploy/README.md);
#                                 security.md (deploy/security/README.md)
#   systemd's unit directory      dnbridge@.service (a template: nothing starts
#                                 until an instance is enabled)
#   /usr/lib/sysusers.d           the dedicated user dnbridge
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

install(TARGETS dnbridge dnbctl cdn127-sim RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(FILES ${PROJECT_SOURCE_DIR}/idl/dnbridge.idl DESTINATION ${CMAKE_INSTALL_DATADIR}/dnbridge/idl)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/cyclonedds/loopback.xml
        DESTINATION ${CMAKE_INSTALL_DATADIR}/dnbridge/cyclonedds)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/config/rack-example.toml
              ${PROJECT_SOURCE_DIR}/deploy/cyclonedds/cyclonedds.xml
        DESTINATION /etc/dnbridge)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/systemd/dnbridge@.service
        DESTINATION ${DNBRIDGE_SYSTEMD_UNIT_DIR})
install(FILES ${PROJECT_SOURCE_DIR}/deploy/systemd/dnbridge.sysusers
        DESTINATION ${DNBRIDGE_SYSUSERS_DIR} RENAME dnbridge.conf)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(PROGRAMS ${PROJECT_SOURCE_DIR}/deploy/security/make-site-pki.sh
        DESTINATION ${CMAKE_INSTALL_DATADIR}/dnbridge/security)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/security/README.md
        DESTINATION ${CMAKE_INSTALL_DOCDIR} RENAME security.md)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR}
        RENAME operations.md)
file(GLOB DNBRIDGE_NETWORKD_EXAMPLES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/deploy/networkd/*.network
     ${PROJECT_SOURCE_DIR}/deploy/networkd/*.link)
install(FILES ${DNBRIDGE_NETWORKD_EXAMPLES} DESTINATION ${CMAKE_INSTALL_DATADIR}/dnbridge/networkd)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/config/cdn127-sim-example.toml
        DESTINATION ${CMAKE_INSTALL_DATADIR}/dnbridge)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME dnbridge)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "dnbridge maintainers <dnbridge@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "DeviceNet master for CDN127 racks, bridged to DDS")
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
    "DeviceNet master for CDN127 racks, bridged to DDS\n\
dnbridge is the DeviceNet master (scanner) of an equipment rack's CAN ports\n\
and publishes the rack's CDN127-fronted pumps as typed DDS topics (Eclipse\n\
Cyclone DDS), taking commands from supervisory programs. Includes dnbctl,\n\
a command-line supervisor, cdn127-sim, a CDN127 simulator for SocketCAN,\n\
the IDL of the data model and the systemd template unit dnbridge@.service.")
set(CPACK_DEBIAN_PACKAGE_SECTION net)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
# Library dependencies as dpkg-shlibdeps finds them in the binaries.
find_program(DNBRIDGE_DPKG_SHLIBDEPS dpkg-shlibdeps)
if(NOT DNBRIDGE_DPKG_SHLIBDEPS)
  message(WARNING "dpkg-shlibdeps (package dpkg-dev) not found: cpack cannot compute Depends")
endif()
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# postinst makes the user with systemd-sysusers, or useradd (passwd) without.
set(CPACK_DEBIAN_PACKAGE_DEPENDS "passwd")
# openssl: make-site-pki.sh, on the host that makes a site's PKI.
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "systemd, openssl")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    "${PROJECT_SOURCE_DIR}/deploy/debian/conffiles;${PROJECT_SOURCE_DIR}/deploy/debian/postinst;${PROJECT_SOURCE_DIR}/deploy/debian/prerm;${PROJECT_SOURCE_DIR}/deploy/debian/postrm")
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
# Debug information stays in the build tree.
set(CPACK_STRIP_FILES ON)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
include(CPack)
