#include "adapters/security/check.hpp"

#include <fmt/format.h>
#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/x509.h>
#include <openssl/x509_vfy.h>
#include <openssl/x509v3.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <string_view>

namespace dnbridge::security {
namespace {

// Owners of OpenSSL objects.
struct Free {
  void operator()(BIO* p) const noexcept { BIO_free(p); }
  void operator()(X509* p) const noexcept { X509_free(p); }
  void operator()(EVP_PKEY* p) const noexcept { EVP_PKEY_free(p); }
  void operator()(X509_STORE* p) const noexcept { X509_STORE_free(p); }
  void operator()(X509_STORE_CTX* p) const noexcept { X509_STORE_CTX_free(p); }
  void operator()(PKCS7* p) const noexcept { PKCS7_free(p); }
};
template <class T>
using Owned = std::unique_ptr<T, Free>;

[[noreturn]] void fail(const std::filesystem::path& file, std::string_view reason) {
  throw CheckError(fmt::format("{}: {}", file.string(), reason));
}

// The last error OpenSSL queued, with its detail ("certificate verify
// error: Verify error: unable to get local issuer certificate"); the queue
// is left empty.
std::string openssl_reason() {
  std::string reason;
  const char* data = nullptr;
  int flags = 0;
  while (const unsigned long e = ERR_get_error_all(nullptr, nullptr, nullptr, &data, &flags)) {
    const char* r = ERR_reason_error_string(e);
    reason = r != nullptr ? r : fmt::format("error {:#x}", e);
    if (data != nullptr && (flags & ERR_TXT_STRING) != 0 && *data != '\0') {
      reason += ": ";
      reason += data;
    }
  }
  return reason.empty() ? "no reason given" : reason;
}

std::string read_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) fail(file, "is a directory, not a file");
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(file, fmt::format("cannot open: {}", std::strerror(errno)));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) fail(file, fmt::format("cannot read: {}", std::strerror(errno)));
  std::string s = std::move(text).str();
  if (s.empty()) fail(file, "is empty");
  return s;
}

Owned<BIO> memory_bio(const std::string& text) {
  Owned<BIO> bio(BIO_new_mem_buf(text.data(), static_cast<int>(text.size())));
  if (!bio) throw std::bad_alloc();
  return bio;
}

std::string utc(const ASN1_TIME* t) {
  std::tm tm{};
  if (ASN1_TIME_to_tm(t, &tm) != 1) return "an unreadable date";
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S UTC", &tm);
  return text;
}

// A certificate's date against `now`: negative before it, positive after.
// X509_cmp_time's 0 is not "equal" but "cannot compare" (a date OpenSSL
// parsed but cannot read as a time): refused, not taken as valid.
int compare_date(const ASN1_TIME* date, std::string_view field, std::time_t now,
                 const std::filesystem::path& file, std::string_view what) {
  const int order = X509_cmp_time(date, &now);
  if (order == 0) fail(file, fmt::format("{} has an unreadable {} date", what, field));
  return order;
}

// A PEM certificate valid at `now`; `what` names it in the message.
Owned<X509> read_certificate(const std::filesystem::path& file, std::string_view what,
                             std::time_t now) {
  const std::string text = read_file(file);
  auto bio = memory_bio(text);
  Owned<X509> cert(PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr));
  if (!cert) {
    ERR_clear_error();
    fail(file, fmt::format("is not a PEM certificate (the {} is one)", what));
  }
  const ASN1_TIME* not_before = X509_get0_notBefore(cert.get());
  if (compare_date(not_before, "notBefore", now, file, what) > 0) {
    fail(file, fmt::format("{} is not valid before {}", what, utc(not_before)));
  }
  const ASN1_TIME* not_after = X509_get0_notAfter(cert.get());
  if (compare_date(not_after, "notAfter", now, file, what) < 0) {
    fail(file, fmt::format("{} expired on {}", what, utc(not_after)));
  }
  return cert;
}

// A store that trusts `ca` only, verifying at `now`.
Owned<X509_STORE> trusting(X509* ca, std::time_t now) {
  Owned<X509_STORE> store(X509_STORE_new());
  if (!store || X509_STORE_add_cert(store.get(), ca) != 1) throw std::bad_alloc();
  X509_VERIFY_PARAM_set_time(X509_STORE_get0_param(store.get()), now);
  return store;
}

void check_signed_by(X509* cert, const std::filesystem::path& file, X509* ca,
                     const std::filesystem::path& ca_file, std::time_t now) {
  auto store = trusting(ca, now);
  Owned<X509_STORE_CTX> ctx(X509_STORE_CTX_new());
  if (!ctx || X509_STORE_CTX_init(ctx.get(), store.get(), cert, nullptr) != 1) {
    throw std::bad_alloc();
  }
  if (X509_verify_cert(ctx.get()) != 1) {
    const int error = X509_STORE_CTX_get_error(ctx.get());
    ERR_clear_error();
    fail(file, fmt::format("identity certificate is not signed by the identity CA {} ({})",
                           ca_file.string(), X509_verify_cert_error_string(error)));
  }
}

// A participant's identity is an end entity. X509_verify_cert takes the
// identity CA's own certificate, and any CA certificate it issued, as signed
// by the identity CA: both refused here.
void check_not_a_ca(X509* cert, const std::filesystem::path& file, X509* ca) {
  constexpr std::string_view kNotAnIdentity =
      "identity certificate is a CA certificate, not a participant's identity";
  if (X509_cmp(cert, ca) == 0) {
    fail(file, fmt::format("{} (it is the identity CA itself)", kNotAnIdentity));
  }
  if (X509_check_ca(cert) != 0) fail(file, kNotAnIdentity);
}

// OpenSSL asks for a pass phrase when a key is encrypted: none is given, and
// no terminal is asked.
extern "C" int no_pass_phrase(char*, int, int, void*) { return -1; }

void check_private_key(const std::filesystem::path& file, X509* cert,
                       const std::filesystem::path& cert_file) {
  const std::string text = read_file(file);
  auto bio = memory_bio(text);
  Owned<EVP_PKEY> key(PEM_read_bio_PrivateKey(bio.get(), nullptr, no_pass_phrase, nullptr));
  if (!key) {
    ERR_clear_error();
    if (text.find("ENCRYPTED") != std::string::npos) {
      fail(file,
           "private key is encrypted: give it unencrypted, readable by this program's "
           "user only");
    }
    fail(file, "is not a PEM private key");
  }
  if (X509_check_private_key(cert, key.get()) != 1) {
    ERR_clear_error();
    fail(file,
         fmt::format("is not the private key of the identity certificate {}", cert_file.string()));
  }
}

// An S/MIME document signed by `ca`, whose content has `element`.
void check_signed_document(const std::filesystem::path& file, std::string_view what,
                           std::string_view element, X509* ca, const std::filesystem::path& ca_file,
                           std::time_t now) {
  const std::string text = read_file(file);
  auto bio = memory_bio(text);
  BIO* content_raw = nullptr;
  Owned<PKCS7> p7(SMIME_read_PKCS7(bio.get(), &content_raw));
  Owned<BIO> content(content_raw);
  if (!p7) {
    ERR_clear_error();
    fail(file, fmt::format("is not an S/MIME signed document (the {} is one: openssl smime "
                           "-sign -text)",
                           what));
  }
  auto store = trusting(ca, now);
  Owned<BIO> out(BIO_new(BIO_s_mem()));
  if (!out) throw std::bad_alloc();
  // PKCS7_TEXT: the signed part is text/plain, as Cyclone's access control
  // plugin verifies it.
  if (PKCS7_verify(p7.get(), nullptr, store.get(), content.get(), out.get(), PKCS7_TEXT) != 1) {
    fail(file, fmt::format("{} signature does not verify with the permissions CA {} ({})", what,
                           ca_file.string(), openssl_reason()));
  }
  char* data = nullptr;
  const long size = BIO_get_mem_data(out.get(), &data);
  if (std::string_view(data, static_cast<std::size_t>(size)).find(element) ==
      std::string_view::npos) {
    fail(file, fmt::format("is signed, but it is not a {} (no {} in it)", what, element));
  }
}

std::string subject_of(X509* cert) {
  Owned<BIO> bio(BIO_new(BIO_s_mem()));
  if (!bio) throw std::bad_alloc();
  X509_NAME_print_ex(bio.get(), X509_get_subject_name(cert), 0, XN_FLAG_RFC2253);
  char* data = nullptr;
  const long size = BIO_get_mem_data(bio.get(), &data);
  return std::string(data, static_cast<std::size_t>(size));
}

void check_plugins(const Settings& s) {
  if (s.plugin_directory.empty()) return;  // by name: only the loader knows
  for (std::string_view plugin : {"auth", "ac", "crypto"}) {
    const auto library = plugin_library(s, plugin);
    if (access(library.c_str(), R_OK) != 0) {
      fail(library, fmt::format("Cyclone DDS security plugin: {} (Debian package libddsc0debian; "
                                "or set [security] plugins to the directory that has it)",
                                std::strerror(errno)));
    }
  }
}

}  // namespace

Identity check(const Settings& s, std::time_t now) {
  auto identity_ca = read_certificate(s.identity_ca, "identity CA", now);
  auto cert = read_certificate(s.certificate, "identity certificate", now);
  check_not_a_ca(cert.get(), s.certificate, identity_ca.get());
  check_signed_by(cert.get(), s.certificate, identity_ca.get(), s.identity_ca, now);
  check_private_key(s.private_key, cert.get(), s.certificate);
  auto permissions_ca = read_certificate(s.permissions_ca, "permissions CA", now);
  check_signed_document(s.governance, "governance document", "<domain_access_rules>",
                        permissions_ca.get(), s.permissions_ca, now);
  check_signed_document(s.permissions, "permissions document", "<permissions>",
                        permissions_ca.get(), s.permissions_ca, now);
  check_plugins(s);
  return Identity{subject_of(cert.get()), utc(X509_get0_notAfter(cert.get()))};
}

}  // namespace dnbridge::security
