# Builds and installs the projfluid C library:
#   make install PREFIX=/opt/projfluid
# installs lib/libprojfluid.{a,so} (stripped of debugging information), include/projfluid.h
# and lib/pkgconfig/projfluid.pc.
# `make install-files BUILT=dir` installs already built libraries from `dir` without building.

PREFIX ?= /usr/local
LIBDIR ?= $(PREFIX)/lib
INCLUDEDIR ?= $(PREFIX)/include
CARGO ?= cargo
CARGO_TARGET_DIR ?= target
BUILT ?= $(CARGO_TARGET_DIR)/release
VERSION := $(shell sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -n 1)
INSTALL ?= install
STRIP ?= strip

.PHONY: all build install install-files uninstall

all: build

# The workspace's libraries (projfluid's and the command line's): built for the whole
# workspace, the dependencies get the features `cargo run --release` and `cargo test --release`
# give them, so the three commands share one build; building projfluid alone would compile
# serde, faer and projfluid again with other features.
build:
	$(CARGO) build --release --workspace --lib

install: build install-files

install-files:
	$(INSTALL) -d $(DESTDIR)$(LIBDIR)/pkgconfig $(DESTDIR)$(INCLUDEDIR)
	$(INSTALL) -m 644 $(BUILT)/libprojfluid.a $(DESTDIR)$(LIBDIR)/libprojfluid.a
	$(INSTALL) -m 755 $(BUILT)/libprojfluid.so $(DESTDIR)$(LIBDIR)/libprojfluid.so
	$(STRIP) --strip-debug $(DESTDIR)$(LIBDIR)/libprojfluid.a $(DESTDIR)$(LIBDIR)/libprojfluid.so
	$(INSTALL) -m 644 include/projfluid.h $(DESTDIR)$(INCLUDEDIR)/projfluid.h
	sed -e 's|@PREFIX@|$(PREFIX)|g' -e 's|@LIBDIR@|$(LIBDIR)|g' \
	    -e 's|@INCLUDEDIR@|$(INCLUDEDIR)|g' -e 's|@VERSION@|$(VERSION)|g' \
	    pkgconfig/projfluid.pc.in > $(DESTDIR)$(LIBDIR)/pkgconfig/projfluid.pc

uninstall:
	rm -f $(DESTDIR)$(LIBDIR)/libprojfluid.a $(DESTDIR)$(LIBDIR)/libprojfluid.so \
	    $(DESTDIR)$(INCLUDEDIR)/projfluid.h $(DESTDIR)$(LIBDIR)/pkgconfig/projfluid.pc
