#pragma once
// Checks the files of a participant's DDS Security before Cyclone DDS gets
// them, with OpenSSL, as the built-in plugins will take them: so that a
// program refuses to start with one line that names the file and says what
// is wrong with it, rather than with a participant that Cyclone refuses or
// that silently never matches anyone.
//
// Checked, in this order: each file can be read; the identity CA, the
// identity certificate and the permissions CA are PEM certificates valid at
// `now` (a date OpenSSL cannot read is an error, not a pass); the
// certificate is not a CA certificate (nor the identity CA itself) and is
// signed by the identity CA; the private key is a PEM key (not encrypted)
// and is the certificate's; the governance and permissions documents are
// S/MIME signed by the permissions CA and hold what their names say; the
// plugin libraries exist. Not checked (Cyclone DDS reports them when it
// creates the participant): whether the documents cover the participant's
// domain and whether a grant names its subject.
#include <ctime>
#include <stdexcept>
#include <string>

#include "adapters/security/settings.hpp"

namespace dnbridge::security {

// "FILE: what is wrong with it", one line.
class CheckError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Who the participant will be, for the log.
struct Identity {
  std::string subject;      // RFC 2253: "CN=rack-A,OU=bridge,O=site"
  std::string valid_until;  // "2027-11-22 09:15:44 UTC"
};

// Throws CheckError for the first file that is wrong.
Identity check(const Settings& settings, std::time_t now = std::time(nullptr));

}  // namespace dnbridge::security
