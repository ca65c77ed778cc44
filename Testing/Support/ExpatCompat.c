/* SPDX-License-Identifier: BSD-3-Clause
 * A preload library that gives ParaView 5.11's XML readers the expat they were written for.
 *
 * Debian 12's expat security updates (2.5.0-1+deb12u2 and later) carry expat 2.6's "reparse deferral" (the fix
 * of CVE-2023-52425): a parser fed a buffer in pieces may wait for more input before it reports a start tag.
 * VTK 9.2's vtkXMLParser (ParaView 5.11) feeds the header of a file with raw appended data and stops at the
 * <AppendedData> tag; with deferral the parser reads on into the binary data and fails with "not well-formed
 * (invalid token)" (VTK issue 19258, fixed in VTK 9.3.1 by switching deferral off per parser). It breaks reading
 * .vtu/.vtp/.vti files written with raw appended data (VTK's default) and RedistributeDataSet, which exchanges
 * pieces in that format. Preloaded (LD_PRELOAD), this library wraps XML_ParserCreate and XML_ParserCreateNS and
 * switches the deferral off in each new parser, as VTK 9.3.1 does; with an expat without the call it changes
 * nothing. The tests run with it (Testing/CMakeLists.txt); users on an updated Debian 12 can preload it as well.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <expat.h>

typedef XML_Parser (*CreateFunction)(const XML_Char*);
typedef XML_Parser (*CreateNSFunction)(const XML_Char*, XML_Char);
typedef XML_Bool (*DeferralFunction)(XML_Parser, XML_Bool);

/* expat's own definition of `name`: the next one after this library in the global scope, or, when expat was
 * loaded privately by a dlopen'ed module (Mesa's drivers in an X server, say: RTLD_NEXT does not see it), the
 * one of libexpat.so.1 itself. */
static void* Real(const char* name)
{
  void* symbol = dlsym(RTLD_NEXT, name);
  if (!symbol)
  {
    void* expat = dlopen("libexpat.so.1", RTLD_LAZY | RTLD_LOCAL);
    symbol = expat ? dlsym(expat, name) : NULL;
  }
  return symbol;
}

static XML_Parser NoDeferral(XML_Parser parser)
{
  /* Present only in expat 2.6 and in the Debian packages that carry its fix. */
  DeferralFunction setDeferral = (DeferralFunction)Real("XML_SetReparseDeferralEnabled");
  if (parser && setDeferral)
  {
    setDeferral(parser, XML_FALSE);
  }
  return parser;
}

XML_Parser XML_ParserCreate(const XML_Char* encoding)
{
  CreateFunction create = (CreateFunction)Real("XML_ParserCreate");
  return create ? NoDeferral(create(encoding)) : NULL;
}

XML_Parser XML_ParserCreateNS(const XML_Char* encoding, XML_Char separator)
{
  CreateNSFunction create = (CreateNSFunction)Real("XML_ParserCreateNS");
  return create ? NoDeferral(create(encoding, separator)) : NULL;
}
