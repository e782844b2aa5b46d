// The tests' files and refusals: a test's output folder under build/release/test-output, text files written
// and read back, and the message of the sylva::Error a call throws. Qt Core and sylva_core only, so the CORE
// tests use it too.
#pragma once

#include <QByteArray>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QString>
#include <QTest>

#include <functional>
#include <string>

#include "core/base/error.h"

namespace sylva::test {

// SYLVA_TEST_OUTPUT/name, created; emptied first when `fresh`.
inline QString outputDir(const QString& name, bool fresh = true)
{
    const QString dir = QString(SYLVA_TEST_OUTPUT) + "/" + name;
    if (fresh) QDir(dir).removeRecursively();
    QDir().mkpath(dir);
    return dir;
}

// Writes `text` to `path` (its folder made), failing the calling test function when it cannot.
inline void writeText(const QString& path, const QByteArray& text)
{
    QDir().mkpath(QFileInfo(path).absolutePath());
    QFile f(path);
    QVERIFY2(f.open(QIODevice::WriteOnly | QIODevice::Truncate), qPrintable(path));
    QCOMPARE(f.write(text), text.size());
}

// The file's text (UTF-8), empty when it cannot be read.
inline QString readText(const QString& path)
{
    QFile f(path);
    return f.open(QIODevice::ReadOnly) ? QString::fromUtf8(f.readAll()) : QString();
}

// What errorOf answers for a call that throws nothing.
inline const std::string kNoError = "(no error)";

// The message of the sylva::Error that f throws, or kNoError.
inline std::string errorOf(const std::function<void()>& f)
{
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return kNoError;
}

} // namespace sylva::test
